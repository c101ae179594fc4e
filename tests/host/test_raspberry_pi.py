"""The Raspberry Pi example mission (boards/raspberry-pi) is a whole mission folder: with its key
file installed it passes `obsw mission check`, it has the recovery link to the reconfiguration
module, the hardware watchdog and TC authentication, and the systemd unit that
`obsw obc install-service` writes for it passes `systemd-analyze verify`."""

import json
import os
import pathlib
import shutil
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
PI = ROOT / "boards" / "raspberry-pi"
OBSW = [sys.executable, "-m", "obsw_host.cli"]


@pytest.fixture
def installed(tmp_path):
    """The Pi mission as docs/raspberry-pi.md installs it, with its key file where it says."""
    folder = tmp_path / "obsw"
    shutil.copytree(PI, folder)
    keys = tmp_path / "tc.keys"
    subprocess.run(OBSW + ["frames", "keygen", str(keys)], check=True, capture_output=True)
    mission = folder / "mission.json"
    text = mission.read_text()
    assert "/etc/obsw/tc.keys" in text
    mission.write_text(text.replace("/etc/obsw/tc.keys", str(keys)))
    return folder


def obsw(*args):
    return subprocess.run(OBSW + list(args), capture_output=True, text=True, timeout=60)


def test_the_pi_mission_passes_the_check(installed):
    res = obsw("mission", "check", str(installed))
    assert res.returncode == 0, res.stdout + res.stderr
    assert "ok (my-cubesat" in res.stdout


def test_without_its_key_file_the_check_names_it():
    res = obsw("mission", "check", str(PI))
    assert res.returncode != 0
    assert "$.frames.keys" in res.stdout + res.stderr
    assert "/etc/obsw/tc.keys" in res.stdout + res.stderr


def test_the_pi_mission_has_the_recovery_link_watchdog_and_keys(installed):
    res = obsw("obc", "config", str(installed))
    assert res.returncode == 0, res.stderr
    config = json.loads(res.stdout)
    platform = config["platform"]
    assert platform["module_uarts"] == ["/dev/ttyAMA1", "/dev/ttyAMA2"]
    assert platform["watchdog"] == "/dev/watchdog"
    assert config["state"] == "/var/lib/obsw"
    mission = json.loads((installed / "mission.json").read_text())
    assert mission["spacecan"]["interface"] == "socketcan"
    assert mission["frames"]["keys"].endswith("tc.keys")


@pytest.mark.skipif(not shutil.which("systemd-analyze"), reason="needs systemd-analyze (systemd)")
def test_the_unit_install_service_writes_verifies(installed, tmp_path):
    root = tmp_path / "image"
    res = obsw("obc", "install-service", str(installed), "--user", "root", "--root", str(root))
    assert res.returncode == 0, res.stderr
    unit = root / "etc" / "systemd" / "system" / "obsw.service"
    env = dict(os.environ, SYSTEMD_LOG_LEVEL="warning")
    verify = subprocess.run(["systemd-analyze", "verify", str(unit)], capture_output=True,
                            text=True, env=env)  # fmt: skip
    assert verify.returncode == 0, verify.stderr
    assert "ExecStart=" in unit.read_text()
