"""Secure by default: an OBC whose mission runs the frame processor refuses to start, with one
line and exit status 2, unless it has usable key material or says "tc_security": "none" (and
then every start logs that commanding is unauthenticated)."""

import json
import os
import shutil

import pytest
from obsw_host.cli import main
from obsw_host.frames import keys, policy
from obsw_host.mission import config as obc_config
from obsw_host.obc.frames_unit import FramesUnit
from obsw_host.obc.topology import Topology
from obsw_host.sample import MISSION_DIR, MISSION_PATH


def mission(tmp_path, **frames):
    """A copy of the sample mission folder whose one process runs the frame processor."""
    folder = tmp_path / "mission"
    if not folder.exists():
        shutil.copytree(MISSION_DIR, str(folder))
    path = folder / "mission.json"
    with open(MISSION_PATH) as f:
        doc = json.load(f)
    os.makedirs(tmp_path / "state", exist_ok=True)
    doc["state"] = str(tmp_path / "state")
    doc["processes"] = {"frames": ["frames"]}
    doc["frames"] = dict({"uart_a": "pty", "uart_b": "pty"}, **frames)
    path.write_text(json.dumps(doc))
    return str(path)


def refused(capsys, path):
    assert main(["obc", "serve", path]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    return err


def test_no_keys_refuses_to_start(tmp_path, capsys):
    err = refused(capsys, mission(tmp_path))
    assert "frames.keys" in err and "tc_security" in err


def test_missing_or_open_key_file_refuses_to_start(tmp_path, capsys):
    assert "absent.keys" in refused(capsys, mission(tmp_path, keys="absent.keys"))
    path = tmp_path / "tc.keys"
    keys.generate(str(path))
    os.chmod(path, 0o644)
    assert "chmod 600" in refused(capsys, mission(tmp_path, keys=str(path)))


def test_key_file_without_operational_tc_sa_refuses(tmp_path, capsys):
    path = str(tmp_path / "tc.keys")
    sas = keys.generate(path)
    for sa in sas:
        sa.stop()
    keys.write_sas(path, sas, replace=True)
    assert "no operational TC SA" in refused(capsys, mission(tmp_path, keys=path))


def test_tc_security_none_must_be_said_and_is_logged_at_every_start(tmp_path):
    cfg = obc_config.load(mission(tmp_path, tc_security="none"))
    assert policy.check(cfg) is None
    said = []
    topology = Topology(cfg)
    unit = FramesUnit(topology, topology.process("frames"), out=said.append)
    unit.fp.close()
    assert said == [policy.OFF_WARNING]
    with pytest.raises(obc_config.ConfigError):
        policy.check(obc_config.load(mission(tmp_path, tc_security="off")))


def test_keys_given_start_with_sdls(tmp_path):
    path = str(tmp_path / "tc.keys")
    keys.generate(path, algorithm="aes-gcm", tm_vcids=(0,))
    cfg = obc_config.load(mission(tmp_path, keys=path))
    said = []
    topology = Topology(cfg)
    unit = FramesUnit(topology, topology.process("frames"), out=said.append)
    try:
        assert said == []
        assert unit.fp.core.security.sas[1].algorithm == "aes-gcm"
        assert unit.fp.core.mux.security.by_vc[0].spi == keys.TM_SPI_BASE
    finally:
        unit.fp.close()
