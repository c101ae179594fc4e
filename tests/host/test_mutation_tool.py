"""tools/mutation.py: the survivors it explains as equivalent are mutants the modules have, at
the lines it names (a line that moved would let the drawn sample fail on an explained mutant),
and a drawn mutant that survives fails the sample."""

import importlib.util
import pathlib
import shutil

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
spec = importlib.util.spec_from_file_location("mutation", ROOT / "tools" / "mutation.py")
mutation = importlib.util.module_from_spec(spec)
spec.loader.exec_module(mutation)

pytestmark = pytest.mark.skipif(
    shutil.which("cosmic-ray", path=str(pathlib.Path(mutation.sys.executable).parent)) is None,
    reason="needs cosmic-ray (a development dependency)",
)


@pytest.fixture(scope="module")
def tree(tmp_path_factory):
    work = tmp_path_factory.mktemp("mutation")
    mutation.copy_tree(str(work))
    return str(work)


def test_every_equivalent_mutant_is_one_the_module_has(tree):
    modules = sorted({module for module, _, _ in mutation.EQUIVALENT})
    found = {(m, line, op) for m, line, op, _ in mutation.mutants(tree, modules)}
    assert sorted(set(mutation.EQUIVALENT) - found) == []


def test_a_survivor_fails_and_an_equivalent_one_passes(tree, monkeypatch, capsys):
    known = ("pus/tc.py", 134, "ReplaceComparisonOperator_Lt_LtE")
    (mutant,) = [m for m in mutation.mutants(tree, ["pus/tc.py"]) if m[:3] == known]
    assert mutation.check(tree, *mutant)  # explained: passes without running
    monkeypatch.setattr(mutation, "EQUIVALENT", {})
    assert not mutation.check(tree, *mutant)  # the same mutant unexplained: it survives
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("ok ") and out[0].endswith("equivalent")
    assert out[1].startswith("FAIL") and out[1].endswith("survived")
