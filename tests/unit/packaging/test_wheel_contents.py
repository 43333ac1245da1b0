"""What the wheel ships: the packages setuptools finds as pyproject.toml configures it hold the
pipeline only, no test data (testkit/ stays in the checkout) and no module that imports a test
tool or the checkout's own folders."""

from __future__ import annotations

import ast
import sys
from pathlib import Path

import setuptools

if sys.version_info >= (3, 11):
    import tomllib
else:  # pytest depends on tomli where tomllib is missing
    import tomli as tomllib

REPO = Path(__file__).resolve().parents[3]
#: Top-level names that are test tools or folders of the checkout, never of an installed package.
NOT_SHIPPED = {"pytest", "hypothesis", "testkit", "tests", "bench", "tools"}


def shipped_packages() -> tuple[Path, list[str]]:
    """The source root and the packages a wheel build finds there: pyproject's
    ``[tool.setuptools.packages.find]``, namespace packages included as setuptools does."""
    config = tomllib.loads((REPO / "pyproject.toml").read_text())
    find = config["tool"]["setuptools"]["packages"]["find"]
    (where,) = find.get("where", ["."])
    finder = (setuptools.find_namespace_packages if find.get("namespaces", True)
              else setuptools.find_packages)
    root = REPO / where
    packages = finder(where=str(root), include=find.get("include", ["*"]),
                      exclude=find.get("exclude", []))
    return root, sorted(packages)


def shipped_modules() -> list[Path]:
    """The .py files of the shipped packages."""
    root, packages = shipped_packages()
    return sorted(p for name in packages for p in (root / name.replace(".", "/")).glob("*.py"))


def imported_roots(path: Path) -> set[str]:
    """The top-level names a module imports, anywhere in it (absolute imports only)."""
    roots = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            roots |= {alias.name.split(".")[0] for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            roots.add(node.module.split(".")[0])
    return roots


def test_the_wheel_holds_pcmapq_and_no_test_data():
    _, packages = shipped_packages()
    assert "pcmapq" in packages and "pcmapq.core" in packages
    assert [p for p in packages if p.split(".")[0] != "pcmapq"] == []
    assert [p for p in packages
            if any(part in {"testing", "testkit", "tests"} for part in p.split("."))] == []


def test_no_shipped_module_imports_a_test_tool_or_the_checkout():
    modules = shipped_modules()
    assert len(modules) > 100
    found = {str(p.relative_to(REPO)): sorted(imported_roots(p) & NOT_SHIPPED) for p in modules}
    assert {k: v for k, v in found.items() if v} == {}
