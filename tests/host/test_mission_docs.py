"""docs/mission.md agrees with the shipped schemas (every key, its default and meaning), and
the shell examples of docs/mission.md and docs/fly-your-own-spacecraft.md run as written."""

import os
import re
import shutil
import subprocess
import sys

import mission_ports
import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
DOCS = os.path.join(ROOT, "docs")
BIN = os.path.dirname(sys.executable)
ENV = dict(os.environ, PATH=BIN + os.pathsep + os.environ.get("PATH", ""))
ENV.pop("OBSW_MISSION", None)


WAIT_FOR_OUTCOME = (
    "for i in $(seq 40); do obsw obcp --mission missions/my-sat status"
    " | grep -q 'last outcome' && break; sleep 0.25; done"
)


def sh_lines(name):
    with open(os.path.join(DOCS, name)) as f:
        text = f.read()
    out = []
    for block in re.findall(r"```sh\n(.*?)```", text, re.S):
        out += [line for line in block.splitlines() if line.strip()]
    return out


def run(line, cwd):
    return subprocess.run(["bash", "-c", line], cwd=cwd, env=ENV, capture_output=True,
                          text=True, timeout=120)  # fmt: skip


def test_the_key_tables_are_the_schemas():
    r = subprocess.run([sys.executable, os.path.join(ROOT, "tools", "mission_reference.py"),
                        "--check"], capture_output=True, text=True)  # fmt: skip
    assert r.returncode == 0, r.stderr


def test_every_schema_key_is_in_the_page():
    from obsw_host.mission import defaults

    with open(os.path.join(DOCS, "mission.md")) as f:
        page = f.read()
    for which in (defaults.MISSION_SCHEMA, defaults.SDB_SCHEMA):
        for key in defaults.schema(which)["properties"]:
            assert "| `%s` |" % key in page, key


def test_the_schema_defaults_are_the_obcs():
    """The defaults an editor shows (the schema's) are the ones the OBC uses."""
    from obsw_host.mission import defaults

    for name, values in defaults.SECTIONS.items():
        assert defaults.schema_section(name) == values, name


@pytest.fixture
def workdir(tmp_path):
    os.symlink(os.path.join(ROOT, "examples"), tmp_path / "examples")
    return tmp_path


def test_mission_page_examples_run(workdir):
    lines = sh_lines("mission.md")
    assert len(lines) >= 4
    for line in lines:
        r = run(line, str(workdir))
        assert r.returncode == 0, (line, r.stdout, r.stderr)
    assert '"format": 2' in (workdir / "old.json").read_text()


@pytest.mark.skipif(shutil.which("java") is None, reason="the guide's Yamcs step needs Java")
def test_the_guide_runs_from_an_empty_folder(workdir):
    """Every line of the guide in one shell, as a reader types them (the OBC in the
    background; before the first ground command, wait until it answers)."""
    # my-sat's ports (base + its APIDs, 1616 to 1621) of this run's own, as a reader with another
    # OBC on the default ports would set them
    ENV["OBSW_PORT_BASE"] = str(mission_ports.free_base(range(1610, 1630)))
    script = ["set -e"]
    for line in sh_lines("fly-your-own-spacecraft.md"):
        script.append(line)
        if " activate " in line:  # a reader looks at the status once the procedure ran
            script.append(WAIT_FOR_OUTCOME)
        if line.startswith("obsw obc serve"):
            script.append("for i in $(seq 60); do obsw ground --mission missions/my-sat "
                          "--timeout 0.5 ping >/dev/null 2>&1 && break; "
                          "sleep 0.5; done")  # fmt: skip
    script.append("kill %1 && wait")  # the reader's Ctrl-C
    r = run("\n".join(script), str(workdir))  # within run's 120 s deadline
    assert r.returncode == 0, (r.stdout[-3000:], r.stderr[-3000:])
    assert "ok (my-sat;" in r.stdout
    assert (workdir / "missions" / "my-sat" / "components" / "magnetorquer.py").is_file()
    assert "alive" in r.stdout
    assert "last outcome confirmed" in r.stdout
