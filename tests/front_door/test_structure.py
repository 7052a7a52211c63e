"""The shape of the code (docs/architecture.md): layers import downwards only, no module uses
another module's private names, small rooms (files ≤ 600 lines, functions ≤ 100 lines), and only
the family registry dispatches on family names."""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[2] / "src" / "screwkit"

#: layer rank of each top-level package/module; a module may import ranks ≤ its own
RANK = {"errors": 0, "constants": 0, "budget": 0, "tables": 0, "messages": 0, "dual": 1,
        "algebraic": 1, "model": 2, "kinematics": 3, "mobility": 3,
        "dynamics": 4, "balancing": 5, "synthesis": 5, "io": 6, "pipeline": 7, "report": 7,
        "sweep": 7, "simulation": 7, "exchange": 7, "studio": 8, "cli": 8, "__init__": 9}


def _modules() -> list[tuple[Path, ast.Module]]:
    out = []
    for path in sorted(SRC.rglob("*.py")):
        if "static" in path.parts or "frontend" in path.parts:
            continue
        out.append((path, ast.parse(path.read_text(encoding="utf-8"))))
    return out


def _package(path: Path) -> str:
    rel = path.relative_to(SRC).parts
    return rel[0].removesuffix(".py")


def _imports(tree: ast.Module) -> list[tuple[str, list[str], int]]:
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module:
            found.append((node.module, [a.name for a in node.names], node.lineno))
        elif isinstance(node, ast.Import):
            found.extend((a.name, [], node.lineno) for a in node.names)
    return found


def test_layers_import_downwards_only():
    bad = []
    for path, tree in _modules():
        own = RANK.get(_package(path))
        if own is None:
            continue
        for module, _, line in _imports(tree):
            parts = module.split(".")
            if parts[0] != "screwkit" or len(parts) < 2:
                continue
            rank = RANK.get(parts[1])
            if rank is not None and rank > own:
                bad.append(f"{path.relative_to(SRC)}:{line} imports {module}")
    assert not bad, "imports against the layers:\n" + "\n".join(bad)


def test_no_module_imports_another_modules_private_names():
    bad = []
    for path, tree in _modules():
        for module, names, line in _imports(tree):
            if module.startswith("screwkit"):
                bad += [f"{path.relative_to(SRC)}:{line} {module}.{n}" for n in names
                        if n.startswith("_") and not n.startswith("__")]
        for node in ast.walk(tree):
            # module._name through an imported module alias (not self/cls attributes)
            if (isinstance(node, ast.Attribute) and node.attr.startswith("_")
                    and not node.attr.startswith("__") and isinstance(node.value, ast.Name)
                    and node.value.id not in ("self", "cls")
                    and node.value.id[:1].islower() and len(node.value.id) <= 3):
                bad.append(f"{path.relative_to(SRC)}:{node.lineno} {node.value.id}.{node.attr}")
    assert not bad, "private names used across modules:\n" + "\n".join(bad)


def test_rooms_are_small():
    long_files, long_functions = [], []
    for path, tree in _modules():
        lines = len(path.read_text(encoding="utf-8").splitlines())
        if lines > 600:
            long_files.append(f"{path.relative_to(SRC)} ({lines} lines)")
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                n = node.end_lineno - node.lineno + 1  # type: ignore[operator]
                if n > 100:
                    long_functions.append(f"{path.relative_to(SRC)}:{node.lineno} {node.name} ({n})")
    assert not long_files, "files over 600 lines:\n" + "\n".join(long_files)
    assert not long_functions, "functions over 100 lines:\n" + "\n".join(long_functions)


def test_only_the_registry_compares_family_names():
    bad = []
    for path, tree in _modules():
        if path.name == "registry.py":
            continue
        for node in ast.walk(tree):
            if isinstance(node, ast.Compare):
                sides = [node.left, *node.comparators]
                if any(isinstance(s, ast.Attribute) and s.attr == "family" for s in sides):
                    bad.append(f"{path.relative_to(SRC)}:{node.lineno}")
    assert not bad, "family-name dispatch outside kinematics/registry.py:\n" + "\n".join(bad)


def test_user_errors_are_screwkit_errors():
    """A bad argument raises a ScrewkitError that is also the built-in a Python user expects
    (InputError is a ValueError, InputTypeError a TypeError, UnknownNameError a KeyError), so
    ``except screwkit.ScrewkitError`` catches every user mistake (docs/reliability.md)."""
    bad = []
    for path, tree in _modules():
        if path.name == "errors.py" and path.parent == SRC:
            continue
        for node in ast.walk(tree):
            if isinstance(node, ast.Raise) and node.exc is not None:
                exc = node.exc.func if isinstance(node.exc, ast.Call) else node.exc
                if isinstance(exc, ast.Name) and exc.id in ("ValueError", "TypeError",
                                                            "KeyError"):
                    bad.append(f"{path.relative_to(SRC)}:{node.lineno} raises {exc.id}")
    assert not bad, "raise the screwkit.errors classes instead:\n" + "\n".join(bad)


def test_every_exception_class_is_a_screwkit_error():
    """Every public exception class screwkit defines derives from ScrewkitError, so one
    ``except`` catches every user mistake (docs/reliability.md); private ones (``_TimeUp``)
    are control flow that never leaves its module."""
    import importlib
    import inspect
    import pkgutil

    import screwkit
    from screwkit.errors import ScrewkitError

    bad = []
    for info in pkgutil.walk_packages(screwkit.__path__, "screwkit."):
        module = importlib.import_module(info.name)
        for name, obj in vars(module).items():
            if (inspect.isclass(obj) and issubclass(obj, BaseException)
                    and obj.__module__ == info.name and not name.startswith("_")
                    and not issubclass(obj, ScrewkitError)):
                bad.append(f"{info.name}.{name}")
    assert not bad, "exception classes outside the ScrewkitError hierarchy: " + ", ".join(bad)
