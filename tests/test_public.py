"""The public surface explains itself (issue 36): what ``bifilar`` and ``bifilar.identification`` export
resolves, their docstrings' examples run, every dotted path the project writes for a reader
(``bifilar.rig.file.load_rig``, ``:mod:`validate.engines.mjcf```) names something that imports, and
every file path from the project's folder (``bifilar/rig/file.py``, ``models/rigs/plate.toml``) exists.

The paths are read from the docstrings and comments of every Python file, every string of the shipped
packages (``bifilar/``, ``validate/``: messages and generated text such as the MJCF comment), and the
Markdown and MJCF files; each must import as its longest module prefix and then resolve by getattr.
"""

import ast
import doctest
import functools
import importlib
import io
import os
import re
import subprocess
import sys
import tokenize
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PUBLIC = ("bifilar", "bifilar.identification")

# A dotted name starting at a word boundary (not inside a longer name, path or file name): a leading
# `~` or `!` of a Sphinx role, backticks and trailing punctuation fall outside the match.
PATH = re.compile(r"(?<![\w./-])(?:bifilar|validate)(?:\.[A-Za-z_]\w*)+(?![\w/-])")
SHIPPED = ("bifilar", "validate")  # every string of these counts; elsewhere docstrings and comments only
PYTHON = ("bifilar", "validate", "tests", "benchmarks", "docs", "models")
TEXT = ("*.md", "docs/*.md", "models/**/*.md", "models/**/*.xml")
# A file or folder of the project by its path from the project's folder; one followed by `{`, `*` or `<`
# is a pattern (``models/rigs/thesis_7_1_lin{1,2,3}.toml``), not a path.
FILE = re.compile(r"(?<![\w./-])(?:bifilar|validate|tests|docs|models|benchmarks)/[\w./-]*\w(?![\w/{*<])")
# Written on purpose as a pattern or a place outside the checkout, not a path: name -> why.
PLACEHOLDERS = {
    "validate.cases.GROUP": "validate/report/junit.py: a test case's classname, GROUP its module",
    "validate/_models": "the models/ folder inside an installed wheel (setup.py)",
}


@pytest.mark.parametrize("name", PUBLIC)
def test_exports_resolve(name):
    module = importlib.import_module(name)
    assert module.__all__ == sorted(set(module.__all__))
    for export in module.__all__:
        assert getattr(module, export) is not None, export
        assert export in dir(module), export
    with pytest.raises(AttributeError):
        module.no_such_name  # noqa: B018


@pytest.mark.parametrize("name", PUBLIC)
def test_docstring_example_runs(name, monkeypatch):
    monkeypatch.chdir(ROOT)  # the examples read models/rigs/ as a user in the project's folder would
    module = importlib.import_module(name)
    assert ">>>" in module.__doc__
    result = doctest.testmod(module, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0 and result.failed == 0


def test_import_bifilar_is_light():
    # The exports load on first use: a fresh interpreter's `import bifilar` imports none of them.
    code = ("import sys, bifilar, bifilar.identification; "
            "print(sorted(m for m in sys.modules if m.startswith('bifilar') or m in ('numba', 'scipy')))")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT,
                         env=env).stdout
    assert out.split() == ["['bifilar',", "'bifilar.identification',", "'bifilar.jit']"]


def _python_texts(path, every_string):
    """The docstrings and comments of a Python file (``every_string``: all its string literals)."""
    source = path.read_text(encoding="utf-8")
    texts = [tok.string for tok in tokenize.generate_tokens(io.StringIO(source).readline)
             if tok.type == tokenize.COMMENT]
    tree = ast.parse(source, str(path))
    if every_string:
        texts += [node.value for node in ast.walk(tree)
                  if isinstance(node, ast.Constant) and isinstance(node.value, str)]
    else:
        texts += [doc for node in ast.walk(tree)
                  if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef))
                  and (doc := ast.get_docstring(node, clean=False))]
    return texts


@functools.cache
def _texts():
    """(file, [text, ...]) of the project's docs, docstrings and comments (and shipped strings)."""
    files = [(path, _python_texts(path, path.relative_to(ROOT).parts[0] in SHIPPED))
             for folder in PYTHON for path in sorted((ROOT / folder).rglob("*.py"))]
    files += [(path, [path.read_text(encoding="utf-8")]) for pattern in TEXT for path in sorted(ROOT.glob(pattern))]
    return files


def _written(pattern):
    """{what ``pattern`` matches: [file, ...]} over :func:`_texts`."""
    found = {}
    for path, texts in _texts():
        for text in texts:
            for match in pattern.finditer(text):
                found.setdefault(match.group(), []).append(str(path.relative_to(ROOT)))
    return found


def _written_paths():
    """{dotted path: [file, ...]} for every path written in the project's docs, docstrings and comments."""
    return _written(PATH)


def _resolves(dotted):
    parts = dotted.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except ModuleNotFoundError as exc:
            if exc.name is None or not dotted.startswith(exc.name):
                raise  # a module that exists but fails to import is not a stale path
            continue
        for part in parts[cut:]:
            if not hasattr(obj, part):
                return False
            obj = getattr(obj, part)
        return True
    return False


def test_reader_finds_paths():
    # A guard on the reader: roles, tildes, backticks and a sentence's full stop around a path.
    text = "see :func:`~bifilar.rig.file.load_rig`, `validate.cli`. Not bifilar-validate/x nor my.bifilar.x"
    assert PATH.findall(text) == ["bifilar.rig.file.load_rig", "validate.cli"]
    assert _resolves("bifilar.rig.file.load_rig") and not _resolves("bifilar.statics.rest_pose")
    found = _written_paths()
    assert len(found) > 100 and "bifilar.rig.statics.rest_pose" in found
    text = "(`models/rigs/plate.toml`), docs/air.md. Not models/rigs/lin{1,2}.toml, a/docs/x nor out/<rig>"
    assert FILE.findall(text) == ["models/rigs/plate.toml", "docs/air.md"]
    assert "validate/engines/mjcf.py" in _written(FILE)


def test_every_written_dotted_path_imports():
    stale = {path: sorted(set(files)) for path, files in sorted(_written_paths().items())
             if path not in PLACEHOLDERS and not _resolves(path)}
    assert not stale, "dotted paths that do not import (path: files):\n" + "\n".join(
        f"  {path}: {', '.join(files)}" for path, files in stale.items())


def test_every_written_file_path_exists():
    stale = {path: sorted(set(files)) for path, files in sorted(_written(FILE).items())
             if path not in PLACEHOLDERS and not (ROOT / path).exists()}
    assert not stale, "file paths that do not exist (path: files):\n" + "\n".join(
        f"  {path}: {', '.join(files)}" for path, files in stale.items())
