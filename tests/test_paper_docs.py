"""The full-size paper numbers in the docs are those the committed summaries give.

docs/paper/tables.md is the output of examples/paper/tables.py on docs/paper/*.summary.h5, and the
README's claims table is that table's; a summary reduced again, or a number edited by hand in
either file, fails here.
"""
import sys
from pathlib import Path

from .processes import run_bounded

ROOT = Path(__file__).resolve().parents[1]


def tables():
    res = run_bounded([sys.executable, ROOT / "examples/paper/tables.py", ROOT / "docs/paper"], 300, cwd=ROOT)
    assert res.returncode == 0, res.stderr
    return res.stdout


def test_tables_md_is_what_the_summaries_give():
    assert (ROOT / "docs/paper/tables.md").read_text() == tables()


def test_readme_claims_table_is_the_generated_one():
    text = tables()
    claims = text[text.index("| the paper (Ohmura"):text.index("\n\n## One model")]
    assert len(claims.splitlines()) == 10          # header, rule, eight claims
    assert claims in (ROOT / "README.md").read_text()
