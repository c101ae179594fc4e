"""`obsw keys` against the real frame processor: a key uploaded by OTAR, activated, verified,
an SA re-keyed with it over the link (stop, expire, rekey, start), its ARSN read; keys and SA
states survive a restart of the OBC's frame processor."""

import binascii
import os
import shutil

from obsw.frames import sdls
from obsw.frames.processor import FrameProcessor
from obsw_host.cli import main
from obsw_host.frames import keys
from obsw_host.frames.processor import security_options
from obsw_host.sample import load_sdb

SCID = 0x2A


def obc(folder):
    opts = security_options(os.path.join(folder, "obc.keys"), load_sdb(), None)
    core = FrameProcessor(
        SCID, lambda apid, p: None, security=opts["security"], ep=opts["ep"],
        ep_map=opts["ep_map"], ep_apid=opts["ep_apid"], tm_security=opts["tm_security"],
    )  # fmt: skip
    sent = []
    core.send_packet = lambda packet, vcid=None: sent.append(packet)
    return core, sent


def run(capsys, core, sent, *argv):
    assert main(["keys", *argv]) == 0
    out = capsys.readouterr().out.split()
    core.receive(0, binascii.unhexlify(out[-1]), 0.0)
    assert main(["keys", "reply", binascii.hexlify(sent[-1]).decode()]) == 0
    return capsys.readouterr().out.strip()


def test_rekey_over_the_link_and_restart(tmp_path, capsys):
    ground = str(tmp_path / "ground.keys")
    assert main(["keys", "init", ground, "--tm-vcs", "0"]) == 0
    for suffix in ("", ".keystore"):
        shutil.copy2(ground + suffix, str(tmp_path / ("obc.keys" + suffix)))
    capsys.readouterr()
    core, sent = obc(str(tmp_path))
    k = ["--keys", ground, "--cltu"]
    seq = iter(range(100))

    def step(*argv):
        return run(capsys, core, sent, *argv, *k, "--seq", str(next(seq)))

    assert step("otar", "200") == "otar: done"
    assert step("activate", "200") == "activate: done"
    assert step("inventory") == "inventory: done 1:active 200:active"
    assert step("stop", "1") == "stop: done 0001"
    assert step("expire", "1") == "expire: done 0001"
    assert step("rekey", "1", "200") == "rekey: done 0001"
    assert step("start", "1") == "start: done 0001"
    assert step("status", "1") == "status: done SPI 1 operational"
    new_key = keys.load_keystore(ground + ".keystore").keys[200][1]
    assert core.security.sas[1].key == new_key
    assert step("read-arsn", "1") == "read-arsn: done SPI 1 ARSN 0"
    # a power cycle: the OBC's key file and key store were saved as they changed
    core2, sent2 = obc(str(tmp_path))
    assert core2.security.sas[1].key == new_key
    assert core2.security.sas[1].state == sdls.SA_OPERATIONAL
    assert core2.ep.store.keys[200][0] == 1  # active


def test_verify_and_refusals(tmp_path, capsys):
    ground = str(tmp_path / "ground.keys")
    assert main(["keys", "init", ground]) == 0
    for suffix in ("", ".keystore"):
        shutil.copy2(ground + suffix, str(tmp_path / ("obc.keys" + suffix)))
    capsys.readouterr()
    core, sent = obc(str(tmp_path))
    k = ["--keys", ground, "--cltu"]
    assert run(capsys, core, sent, "start", "1", *k).startswith("start: wrong_sa_state")
    assert run(capsys, core, sent, "activate", "300", *k, "--seq", "1").startswith(
        "activate: unknown_key"
    )
    assert main(["keys", "otar", "5", "--keys", ground]) == 2  # a master key ID
    assert main(["keys", "reply", "zz"]) == 2
