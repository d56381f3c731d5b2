"""The documentation: every example on the user's pages runs, and the site builds without a warning.

The pages' conventions (which blocks run, ``# docs: smoke`` lines) are in ``docs/scripts/doc_blocks.py``.
``MARBELLOUS_DOCS_SMOKE=1 pytest tests/test_docs.py`` runs the pages in full.
"""
import importlib.util
import os
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
sys.path.insert(0, str(DOCS / "scripts"))
import doc_blocks  # noqa: E402

#: the pages whose examples run: home, getting started, the tutorials, the guides and the lecture map
PAGES = sorted([DOCS / "index.md", DOCS / "getting-started.md", DOCS / "viewer.md", DOCS / "game.md",
                DOCS / "levels.md", DOCS / "sweeps.md", *(DOCS / "tutorials").glob("*.md"),
                *(DOCS / "lecture").glob("*.md")])


def _rel(p):
    return str(p.relative_to(DOCS))


def test_conventions():
    """The block parser and the smoke shortening do what doc_blocks' docstring says."""
    text = "# T\n\n```python\nx = 1\n```\n\ntext\n\n```py\nmb.show(w)\n```\n```bash\nmarbellous demo --level a\n```\n"
    got = doc_blocks.blocks(text)
    assert [(b.lang, b.line, b.code) for b in got] == [("python", 4, "x = 1\n"), ("py", 10, "mb.show(w)\n"),
                                                      ("bash", 13, "marbellous demo --level a\n")]
    assert doc_blocks.marbellous_commands("pip install x\nmarbellous demo --level 'my level.toml'\n") == \
        [["demo", "--level", "my level.toml"]]
    code = ("for _ in range(600):  # docs: smoke\n    pass\nfor _ in range(600):\n    pass\n"
            "rec(seconds=4.0)  # docs: smoke")
    assert doc_blocks.shorten(code, 10) == ("for _ in range(60):  # docs: smoke\n    pass\nfor _ in range(600):\n"
                                            "    pass\nrec(seconds=0.4)  # docs: smoke")
    assert doc_blocks.shorten("range(3)  # docs: smoke", 10) == "range(1)  # docs: smoke"


@pytest.mark.parametrize("page", PAGES, ids=_rel)
def test_page_examples_run(page, tmp_path):
    """Every ``python`` block of the page runs, in order, in one namespace (``py`` blocks compile)."""
    found = doc_blocks.blocks(page.read_text(encoding="utf-8"))
    if page.parent.name == "tutorials" or page.name == "getting-started.md":
        assert any(b.lang == "python" for b in found), f"{_rel(page)} has no python example"
    doc_blocks.run_page(page, tmp_path, factor=doc_blocks.smoke_factor(), echo=lambda s: None)


def test_pages_keep_to_the_fences():
    """Code blocks on the run pages are python, py, bash, toml or text: a typo in a fence (```pyhton)
    would silently skip an example."""
    allowed = {"python", "py", "bash", "toml", "text", ""}
    for page in PAGES:
        for b in doc_blocks.blocks(page.read_text(encoding="utf-8")):
            assert b.lang in allowed, f"{_rel(page)}, line {b.line}: code block marked {b.lang!r}"


def test_level_format_example_loads(tmp_path):
    """The complete example on the level format page is a valid level."""
    from marbellous.game.level import load_level

    examples = [b.code for b in doc_blocks.blocks((DOCS / "levels.md").read_text(encoding="utf-8"))
                if b.lang == "toml" and "[start]" in b.code]
    assert examples
    for k, code in enumerate(examples):
        path = tmp_path / f"example{k}.toml"
        path.write_text(code, encoding="utf-8")
        level = load_level(path)
        assert level.colliders and level.path is not None


@pytest.mark.skipif(importlib.util.find_spec("mkdocs") is None or importlib.util.find_spec("mkdocstrings") is None,
                    reason="the docs extra (mkdocs-material, mkdocstrings) is not installed")
def test_site_builds_strict(tmp_path):
    """``mkdocs build --strict``: no broken link, no missing page or image, no docstring warning."""
    done = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")],
                          cwd=ROOT, capture_output=True, text=True, env={**os.environ, "NO_MKDOCS_2_WARNING": "1"})
    assert done.returncode == 0, done.stdout + done.stderr
    assert (tmp_path / "site" / "index.html").is_file()
    assert (tmp_path / "site" / "reference" / "world" / "index.html").is_file()
