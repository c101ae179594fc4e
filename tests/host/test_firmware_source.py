"""A clone without the pinned MicroPython source: the firmware tool fetches the tag's tree and
checks its commit, or says in one line what to provide."""

import pathlib
import subprocess

import pytest
from obsw_host import firmware


@pytest.fixture
def bare_clone(tmp_path, monkeypatch):
    """The firmware tool as in a fresh clone: no shared folder, no $OBSW_MICROPYTHON_SRC."""
    monkeypatch.delenv("OBSW_MICROPYTHON_SRC", raising=False)
    monkeypatch.setattr(firmware, "ROOT", tmp_path / "clone")
    monkeypatch.setattr(firmware, "BUILD", tmp_path / "clone" / "build" / "fw")
    return tmp_path


def _git(*args, cwd):
    subprocess.run(("git", "-c", "user.name=t", "-c", "user.email=t@t") + args, cwd=cwd,
                   check=True, capture_output=True)  # fmt: skip


def _upstream(tmp_path):
    """A repository with the tag the tool asks for (``file://``, no network needed)."""
    up = tmp_path / "upstream"
    (up / "py").mkdir(parents=True)
    (up / "py" / "mpconfig.h").write_text("/* a tree */\n")
    _git("init", "-q", cwd=up)
    _git("add", ".", cwd=up)
    _git("commit", "-q", "-m", "release", cwd=up)
    _git("tag", "v" + firmware.VERSION, cwd=up)
    commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=up, capture_output=True,
                            text=True, check=True).stdout.strip()  # fmt: skip
    return "file://%s" % up, commit


def test_without_a_network_one_line_says_what_to_provide(bare_clone, monkeypatch):
    monkeypatch.setattr(firmware, "GIT_URL", "file://%s/nowhere" % bare_clone)
    with pytest.raises(firmware.FirmwareError) as e:
        firmware.source()
    text = str(e.value)
    assert "\n" not in text
    assert "OBSW_MICROPYTHON_SRC" in text and firmware.ARCHIVE in text
    assert not (firmware.BUILD / ("micropython-%s-git" % firmware.VERSION)).exists()


def test_a_tag_at_another_commit_is_refused(bare_clone, monkeypatch):
    url, commit = _upstream(bare_clone)
    monkeypatch.setattr(firmware, "GIT_URL", url)
    with pytest.raises(firmware.FirmwareError) as e:
        firmware.source()
    assert "is commit %s, not the pinned %s" % (commit, firmware.GIT_COMMIT) in str(e.value)


def test_the_pinned_tag_is_fetched_once(bare_clone, monkeypatch):
    url, commit = _upstream(bare_clone)
    monkeypatch.setattr(firmware, "GIT_URL", url)
    monkeypatch.setattr(firmware, "GIT_COMMIT", commit)
    monkeypatch.setattr(firmware, "GIT_SUBMODULES", ())
    tree = firmware.source()
    assert (tree / "py" / "mpconfig.h").is_file()
    monkeypatch.setattr(firmware, "GIT_URL", "file://%s/nowhere" % bare_clone)
    assert firmware.source() == tree  # no second fetch


def test_no_machine_path_in_the_tool():
    with open(firmware.__file__, encoding="utf-8") as f:
        text = f.read()
    # no path into the folder that holds the checkout (a machine's workspace)
    assert str(pathlib.Path(firmware.ROOT).parent) + "/" not in text
