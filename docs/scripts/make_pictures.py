"""Make the pictures of the getting-started, tutorial and lecture pages by running the pages themselves.

Each page's examples run in a scratch directory (as in the tests, but in full); every PNG an example
writes there that the page shows as ``<page name>/<file>.png`` is copied next to the page, so a picture
is always what the code above it draws.  The figures of measurements are made by the ``plot_*.py``
scripts beside this one.

Run from the repository's root:  python docs/scripts/make_pictures.py [PAGE.md ...]
"""
import os
import shutil
import sys
import tempfile

import doc_blocks

DOCS = os.path.join(doc_blocks.ROOT, "docs")
PAGES = ("getting-started.md", "tutorials/first-world.md", "tutorials/level-from-blender.md",
         "tutorials/training-an-agent.md", "lecture/colliders.md")
#: largest picture the site should carry, bytes
MAX_BYTES = 200_000


def make(page):
    path = os.path.join(DOCS, page)
    with open(path, encoding="utf-8") as f:
        text = f.read()
    stem = os.path.splitext(os.path.basename(page))[0]
    target = os.path.join(os.path.dirname(path), stem)
    with tempfile.TemporaryDirectory() as scratch:
        doc_blocks.run_page(path, scratch, echo=lambda s: None)
        for name in sorted(os.listdir(scratch)):
            if name.endswith(".png") and f"({stem}/{name})" in text:
                os.makedirs(target, exist_ok=True)
                shutil.copy(os.path.join(scratch, name), os.path.join(target, name))
                size = os.path.getsize(os.path.join(target, name))
                print(f"{os.path.relpath(os.path.join(target, name), doc_blocks.ROOT)}: {size // 1000} kB"
                      + ("  (too large)" if size > MAX_BYTES else ""))


if __name__ == "__main__":
    for page in sys.argv[1:] or PAGES:
        make(page)
