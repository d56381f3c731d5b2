"""The package's layers, as docs/architecture.md draws them: every import goes to the importer's own layer
or one below it."""
import ast
import pathlib
import re

import marbellous

PACKAGE = pathlib.Path(marbellous.__file__).parent
DOC = PACKAGE.parent / "docs" / "architecture.md"


def layers():
    """The doc's layer table, top to bottom: a list of module-name patterns per layer."""
    text = DOC.read_text()
    block = re.search(r"<!-- layers -->\n```\n(.*?)```", text, re.S).group(1)
    out = []
    for line in block.splitlines():
        names = line.split("  ")[0].strip()
        if names:
            out.append([n.strip() for n in names.split(",")])
    return out


def layer_of(module, table):
    """Index of the layer whose most specific pattern matches ``module``: ``a.b`` matches ``a.b`` and the
    modules inside it, ``=a.b`` only ``a.b`` itself."""
    best, best_len = None, -1
    for k, patterns in enumerate(table):
        for p in patterns:
            exact = p.startswith("=")
            base = p.lstrip("=")
            if module == base or (not exact and module.startswith(base + ".")):
                if len(base) > best_len:
                    best, best_len = k, len(base)
    return best


def modules():
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE.parent).with_suffix("")
        parts = list(rel.parts)
        is_package = parts[-1] == "__init__"
        if is_package:
            parts = parts[:-1]
        yield ".".join(parts), is_package, path


def imports_of(module, is_package, path):
    """Every marbellous module imported anywhere in the file (inside functions too)."""
    here = module.split(".") if is_package else module.split(".")[:-1]
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.name.startswith("marbellous"):
                    yield a.name
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = here[:len(here) - (node.level - 1)]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if not target.startswith("marbellous"):
                continue
            for a in node.names:             # `from pkg import module` names a module
                sub = f"{target}.{a.name}"
                yield sub if (PACKAGE.parent / (sub.replace(".", "/") + ".py")).exists() \
                    or (PACKAGE.parent / sub.replace(".", "/")).is_dir() else target


def test_every_module_has_a_layer():
    table = layers()
    missing = [m for m, _, _ in modules() if layer_of(m, table) is None]
    assert not missing


def test_imports_go_downward_only():
    table = layers()
    upward = []
    for module, is_package, path in modules():
        mine = layer_of(module, table)
        for target in imports_of(module, is_package, path):
            theirs = layer_of(target, table)
            if theirs is not None and theirs < mine:
                upward.append(f"{module} (layer {mine}) imports {target} (layer {theirs})")
    assert not upward, "\n".join(upward)
