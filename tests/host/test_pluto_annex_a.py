"""PLUTO against the ECSS-E-ST-70-32C Annex A grammar itself (pluto-parser's EBNF): every
procedure generated from the grammar loads; procedures one token away from generated ones are
taken where the reference parser (Lark, Earley, from the same EBNF) takes them and refused with
a line and a column where it refuses them; every alternative and optional clause is taken; and
docs/pluto.md's production table is this run's."""

import random

import pluto_annex_a as annex
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from obsw.pluto.lexer import PlutoSyntaxError
from obsw.pluto.parser import parse
from obsw.pluto.syntax import RESERVED


@pytest.fixture(scope="module")
def run():
    return annex.Run(parse, PlutoSyntaxError, RESERVED)


def test_every_generated_procedure_loads(run):
    assert len(run.texts) >= 2000
    assert not run.refused, "%s in:\n%s" % run.refused[0]


def test_generated_procedures_are_in_the_reference_language(run):
    assert run.checked and not run.outside, run.outside[:1]


def test_one_token_away_agrees_with_the_reference(run):
    assert run.reference_accepts > 0 and run.reference_accepts < run.mutants  # both seen
    assert not run.disagreements, run.disagreements[:1]


def test_every_alternative_and_optional_clause_taken(run):
    assert not run.missing()


def test_docs_table_is_this_run(run):
    with open(annex.PAGE) as f:
        page = f.read()
    assert annex.page_with(run.markdown(), page) == page, (
        "run: python tests/host/pluto_annex_a.py --write"
    )


def test_refusals_name_a_line_and_column():
    # a sample of refused neighbours: the position is inside the text
    gen = annex.Generator(annex.productions(), 7, budget=40)
    rng = random.Random(7)
    words = sorted(annex.keywords(gen.prods))
    seen = 0
    for _ in range(200):
        text = annex.mutant(gen.sentence(), rng, words)
        try:
            parse(text)
        except PlutoSyntaxError as e:
            seen += 1
            assert e.line == 1 and 1 <= e.col <= len(text) + 1, (str(e), text)
    assert seen > 100


PRODS = annex.productions()


@settings(max_examples=150, deadline=None, derandomize=True)
@given(st.randoms(use_true_random=False))
def test_hypothesis_walks_the_grammar(rnd):
    # Hypothesis chooses at every alternative (and shrinks a failure to a short procedure)
    gen = annex.Generator(PRODS, budget=60)
    gen.rng = rnd
    text = gen.text(gen.sentence())
    parse(text)
