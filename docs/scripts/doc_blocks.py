"""Run the code of a documentation page, as the tests and the picture script do.

Conventions of the pages (the tests hold every page to them):

* A fenced block marked ```` ```python ```` is run.  A page's blocks run in order in one namespace, in
  one working directory, so a later block sees what an earlier one defined and the files it wrote.
* A block marked ```` ```py ```` is shown the same way but not run: code that needs a display
  (``mb.show``) or a fragment.  The tests still compile it.
* In a ```` ```bash ```` block, each line that starts with ``marbellous `` is run as that command, at its
  place in the page; other shell lines (installs) are not.
* A line that ends with the comment ``# docs: smoke`` is shortened in the tests: the number in its
  ``range(N)`` or ``seconds=S`` is divided by ``$MARBELLOUS_DOCS_SMOKE`` (default 10; 1 runs the page in
  full).  The line still runs; only its length changes.
"""
import math
import os
import re
import subprocess
import sys
from dataclasses import dataclass

FENCE = re.compile(r"^```(?P<lang>[\w-]*)[^\n]*\n(?P<body>.*?)^```[ \t]*$", re.M | re.S)
SMOKE = "# docs: smoke"
_SHORTEN = re.compile(r"(?P<head>range\(|seconds=)(?P<num>\d+(?:\.\d+)?)")
#: environment variable holding the factor ``# docs: smoke`` lines are shortened by
SMOKE_ENV = "MARBELLOUS_DOCS_SMOKE"
#: the repository's root (the directory holding ``marbellous/``)
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


@dataclass
class Block:
    """A fenced code block: its language, its first line's number in the page (1-based) and its code."""

    lang: str
    line: int
    code: str


def blocks(text):
    """Every fenced code block of a Markdown page, in order."""
    return [Block(m.group("lang"), text.count("\n", 0, m.start()) + 2, m.group("body"))
            for m in FENCE.finditer(text)]


def smoke_factor():
    """The factor ``# docs: smoke`` lines are shortened by (``$MARBELLOUS_DOCS_SMOKE``, default 10)."""
    value = float(os.environ.get(SMOKE_ENV, "10"))
    if not value >= 1.0:
        raise ValueError(f"{SMOKE_ENV} must be a number >= 1, got {value!r}")
    return value


def shorten(code, factor):
    """``code`` with the ``range(N)`` and ``seconds=S`` of each ``# docs: smoke`` line divided by ``factor``."""
    def one(m):
        num = m.group("num")
        if "." in num:
            return f"{m.group('head')}{float(num) / factor:g}"
        return f"{m.group('head')}{max(1, math.ceil(int(num) / factor))}"

    return "\n".join(_SHORTEN.sub(one, line) if line.rstrip().endswith(SMOKE) else line
                     for line in code.split("\n"))


def marbellous_commands(code):
    """The ``marbellous ...`` command lines of a shell block, as argument lists."""
    import shlex

    return [shlex.split(line)[1:] for line in code.splitlines() if line.startswith("marbellous ")]


def run_command(args, cwd):
    """Run ``marbellous ARGS`` with this Python and this checkout of the package; returns the process."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (ROOT, env.get("PYTHONPATH")) if p)
    env.setdefault("MARBELLOUS_DATA_DIR", os.path.join(cwd, ".marbellous-data"))   # best times stay here
    return subprocess.run([sys.executable, "-c", "import sys; from marbellous.cli import main; sys.exit(main())",
                           *args], cwd=cwd, env=env, capture_output=True, text=True)


def run_page(path, cwd, factor=1.0, echo=print):
    """Run the page at ``path`` in the directory ``cwd`` (see the module docstring); returns the namespace.

    Raises ``AssertionError`` naming the page and the block's line when a block or command fails."""
    with open(path, encoding="utf-8") as f:
        text = f.read()
    namespace = {"__name__": "__docs__"}
    old = os.getcwd()
    os.chdir(cwd)
    try:
        for b in blocks(text):
            where = f"{os.path.basename(path)}, block at line {b.line}"
            if b.lang == "python":
                code = compile(shorten(b.code, factor), where, "exec")
                exec(code, namespace)
            elif b.lang == "py":
                compile(b.code, where, "exec")
            elif b.lang == "bash":
                for args in marbellous_commands(b.code):
                    done = run_command(args, cwd)
                    echo(done.stdout)
                    assert done.returncode == 0, (f"{where}: marbellous {' '.join(args)} exited with "
                                                  f"{done.returncode}:\n{done.stdout}\n{done.stderr}")
    finally:
        os.chdir(old)
    return namespace
