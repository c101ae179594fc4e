"""SDLS sequence numbers (the IVs of AES-GCM SAs) never repeat under one key, even when a state
file is deleted or reset (issue 34): the highest number each SA may have sent is kept with
the key in the key file, reserved before use. Through `obsw frames sign` for the ground's TC
SAs, and through the key files of the OBC's TM SAs as the frame processor loads them."""

import json
import os

from obsw_host.cli import main
from obsw_host.frames import keys

PACKET = "1840c0000002616263"


def sign(capsys, key_file):
    assert main(["frames", "sign", "--keys", key_file, PACKET]) == 0
    frame = bytes.fromhex(capsys.readouterr().out.strip())
    return int.from_bytes(frame[8:12], "big")  # HMAC SA: SPI, then a 4-octet number


def test_frames_sign_never_repeats_a_number_when_the_state_file_is_deleted(tmp_path, capsys):
    key_file = str(tmp_path / "tc.keys")
    assert main(["frames", "keygen", key_file]) == 0
    capsys.readouterr()
    used = [sign(capsys, key_file) for _ in range(3)]
    assert used == [1, 2, 3]
    os.remove(key_file + ".state")
    after = sign(capsys, key_file)
    assert after > max(used)
    with open(key_file + ".state", "w") as f:
        f.write("[[1, 0, 0]]")  # a state file reset to zero: numbers never go down
    assert sign(capsys, key_file) > after
    assert os.stat(key_file).st_mode & 0o777 == 0o600


def tm_security(key_file, state):
    _, tm, keeper = keys.load_all(key_file, state)
    return tm, keeper


def ivs_sent(tm, n):
    out = []
    for _ in range(n):
        field = tm.seal(0, b"\x00" * 40)
        out.append(int.from_bytes(field[2:14], "big"))
    return out


def test_tm_ivs_stay_above_every_iv_used_when_either_state_file_is_lost(tmp_path):
    """The OBC's TM SAs (AES-GCM, IVs reserved in blocks of 64): its state file deleted, as
    `obsw obc reset` does, or reset; the next frame's IV is above all used before."""
    key_file = str(tmp_path / "frames.keys")
    keys.generate(key_file, algorithm="aes-gcm", tm_vcids=(0,), allow_git=True)
    state = str(tmp_path / "state" / "frames.keys.state")
    os.makedirs(os.path.dirname(state))
    used = []
    for lose in ("delete", "reset", "corrupt", "delete"):
        tm, keeper = tm_security(key_file, state)
        used += ivs_sent(tm, 70)  # past one reserved block
        if lose == "delete":
            os.remove(state)
        elif lose == "reset":
            with open(state, "w") as f:
                json.dump([[64, 0, 0]], f)
        else:
            with open(state, "w") as f:
                f.write("[" * 5000)
        tm, keeper = tm_security(key_file, state)
        nxt = ivs_sent(tm, 1)[0]
        assert nxt > max(used), (lose, nxt, max(used))
        used.append(nxt)
    assert len(set(used)) == len(used)
    assert os.stat(key_file).st_mode & 0o777 == 0o600
    assert os.path.exists(state + ".bad")  # the corrupt one, set aside


def test_the_key_file_number_is_written_before_the_block_is_used(tmp_path):
    key_file = str(tmp_path / "frames.keys")
    keys.generate(key_file, algorithm="aes-gcm", tm_vcids=(0,), allow_git=True)
    tm, keeper = tm_security(key_file, str(tmp_path / "s"))
    writes = []
    real = keeper.save_floors
    keeper.save_floors = lambda: (writes.append(tm.sas[64].sn_sent), real())[1]
    ivs_sent(tm, 1)
    with open(key_file) as f:
        sent = [e.get("sent") for e in json.load(f)["sas"] if e["spi"] == 64]
    assert writes == [0]  # reserved while no number of the block was used yet
    assert sent == [64]


def test_a_leftover_temporary_file_does_not_make_the_key_file_readable(tmp_path):
    key_file = str(tmp_path / "tc.keys")
    keys.generate(key_file, allow_git=True)
    tmp = key_file + ".tmp"
    with open(tmp, "w") as f:
        f.write("left over")
    os.chmod(tmp, 0o644)
    security, keeper = keys.load(key_file)
    keys.write_sas(key_file, list(security.sas.values()), replace=True)
    assert os.stat(key_file).st_mode & 0o777 == 0o600
    assert not os.path.exists(tmp)
    with open(tmp, "w") as f:
        f.write("left over")
    os.chmod(tmp, 0o666)
    keeper.save()
    assert os.stat(key_file + ".state").st_mode & 0o777 == 0o600
