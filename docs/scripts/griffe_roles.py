"""A griffe extension for the API reference: Sphinx roles in docstrings become links or code.

Marbellous' docstrings use reStructuredText roles (``:class:`World```, ``:meth:`add_body```).  Markdown
would print them as they are, so before mkdocstrings renders a docstring each role becomes a cross-reference
to the public name it means (``[`World`][marbellous.World]``), or plain code when the name is not part of
the documented API.  Used by mkdocs.yml (``extensions:`` of the python handler).
"""
import re

import griffe

ROLE = re.compile(r":(?:class|meth|func|attr|data|mod|obj|exc):`(~?)([\w.]+)`")


def _target(obj):
    """The canonical path an object or alias stands for."""
    return obj.target_path if obj.is_alias else obj.path


class RstRoles(griffe.Extension):
    """Rewrite ``:role:`name``` in every docstring of the package (see the module docstring)."""

    def on_package(self, *, pkg, **kwargs):
        public = {}                    # canonical path -> public path, for the names marbellous exports
        for name in pkg.exports or ():                # the names in marbellous.__all__
            if name in pkg.members and not name.startswith("_"):
                public[_target(pkg.members[name])] = f"{pkg.path}.{name}"
        self.public, self.pkg = public, pkg
        self._walk(pkg, set())

    def _walk(self, obj, seen):
        if obj.is_alias or obj.path in seen:
            return
        seen.add(obj.path)
        if obj.docstring is not None and ":" in obj.docstring.value:
            obj.docstring.value = ROLE.sub(lambda m: self._link(obj, m.group(1), m.group(2)), obj.docstring.value)
        for member in obj.members.values():
            self._walk(member, seen)

    def _resolve(self, obj, name):
        """The canonical path ``name`` refers to from ``obj``'s docstring, or None."""
        if "." in name:
            return name
        scope = obj
        while scope is not None:                     # the object, its class, its module, the package
            if name in scope.members:
                return _target(scope.members[name])
            scope = scope.parent
        return None

    def _public(self, path):
        if path is None:
            return None
        for canonical, public in self.public.items():
            if path == canonical or path.startswith(canonical + "."):
                return public + path[len(canonical):]
        return None

    def _link(self, obj, tilde, name):
        text = name.rsplit(".", 1)[-1] if tilde else name
        target = self._public(self._resolve(obj, name))
        return f"[`{text}`][{target}]" if target else f"`{text}`"
