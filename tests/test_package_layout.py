"""A package's __init__.py names what the package holds (docstring, re-exports, the lazy
``__getattr__`` that loads them on first use); its logic lives in modules named for what they
do (pcmapq.match.one_to_one, pcmapq.io.load, pcmapq.api.calls, ...)."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "pcmapq"
#: Packages whose __init__ still holds logic, to be moved out on their own.
PENDING = ("cli", "settings", "testing", "track")


def inits() -> list[Path]:
    return sorted(p for p in PACKAGE.rglob("__init__.py")
                  if p.relative_to(PACKAGE).parts[0] not in PENDING)


@pytest.mark.unit
@pytest.mark.parametrize("init", inits(), ids=lambda p: str(p.relative_to(PACKAGE.parent)))
def test_a_package_init_defines_no_logic(init):
    """No function but ``__getattr__``, no class, no statement but imports and names."""
    allowed = (ast.Import, ast.ImportFrom, ast.Assign, ast.AnnAssign, ast.If, ast.Expr)
    for node in ast.parse(init.read_text()).body:
        if isinstance(node, ast.FunctionDef) and node.name == "__getattr__":
            continue
        assert isinstance(node, allowed), \
            f"{init}:{node.lineno}: {type(node).__name__} {getattr(node, 'name', '')}"
        if isinstance(node, ast.If):  # only `if TYPE_CHECKING:` imports
            assert ast.unparse(node.test) == "TYPE_CHECKING", f"{init}:{node.lineno}"
            assert all(isinstance(n, ast.Import | ast.ImportFrom) for n in node.body)
        if isinstance(node, ast.Expr):  # the docstring only
            assert isinstance(node.value, ast.Constant) and isinstance(node.value.value, str)
