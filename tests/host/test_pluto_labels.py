"""A function argument with an enumeration takes its labels in PLUTO: `obsw pluto check
--mission` refuses a label the database does not declare (naming the closest one) and a number
that is none of its values, and takes a label, its number, or a string computed at run time."""

import os
import subprocess
import sys

import pytest
from obsw_host.sample import MISSION_DIR

AURORA = os.path.join(os.path.dirname(MISSION_DIR), "aurora")
CALL = "initiate and confirm select_mode of Attitude with arguments mode := %s end with;"


def check(tmp_path, value, decl=""):
    src = tmp_path / "p.plt"
    src.write_text("procedure\n%s  main\n    %s\n  end main\nend procedure\n"
                   % (decl, CALL % value))  # fmt: skip
    return subprocess.run([sys.executable, "-m", "obsw_host.cli", "pluto", "check", str(src),
                           "--mission", AURORA], capture_output=True, text=True)  # fmt: skip


@pytest.mark.parametrize("value", ['"DETUMBLE"', '"POINTING"', "2"])
def test_a_label_or_its_number(tmp_path, value):
    res = check(tmp_path, value)
    assert res.returncode == 0, res.stdout + res.stderr


@pytest.mark.parametrize("value, why", [
    ('"FAST"', "no label 'FAST'"),
    ('"DETUMBEL"', "no label 'DETUMBEL'; did you mean 'DETUMBLE'?"),
    ("7", "no label numbered 7"),
])  # fmt: skip
def test_not_a_label(tmp_path, value, why):
    res = check(tmp_path, value)
    assert res.returncode == 1
    out = res.stdout + res.stderr
    assert "argument mode takes one of OFF, DETUMBLE, POINTING" in out and why in out, out
