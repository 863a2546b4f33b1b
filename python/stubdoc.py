"""Copy the docstrings of the built module (``hylc._hylc``, written as Rust doc comments in ``src/``) into the
stub ``hylc/_hylc.pyi``, so that editors and type checkers show them:

    python python/stubdoc.py          # rewrite the stub
    python python/stubdoc.py --check  # exit 1 when the stub's docstrings differ (tests/test_stub.py checks too)

Every class, function, method and property of the stub that the module has gets the module's docstring; the
stub's own classes (the TypedDicts of the returned dicts) keep theirs; ``__init__`` and other dunders are skipped
(the class docstring documents the constructor)."""

import ast
import inspect
import sys
from pathlib import Path

STUB = Path(__file__).resolve().parent / "hylc" / "_hylc.pyi"


def runtime_docs(tree, module):
    """(node, docstring) for every stub definition the module documents."""
    out = []
    for node in tree.body:
        if not isinstance(node, (ast.FunctionDef, ast.ClassDef)) or not hasattr(module, node.name):
            continue
        obj = getattr(module, node.name)
        out.append((node, inspect.getdoc(obj)))
        if isinstance(node, ast.ClassDef):
            for item in node.body:
                if isinstance(item, ast.FunctionDef) and not item.name.startswith("__"):
                    member = inspect.getattr_static(obj, item.name, None)
                    doc = getattr(member, "__doc__", None) if member is not None else None
                    out.append((item, inspect.cleandoc(doc) if doc else None))
    return [(n, d) for n, d in out if d]


def quoted(doc, indent):
    prefix = "r" if "\\" in doc else ""
    lines = doc.splitlines()
    body = [f'{indent}{prefix}"""{lines[0]}'] + [f"{indent}{line}" if line else "" for line in lines[1:]]
    if len(lines) == 1:
        return [body[0] + '"""']
    return body + [f'{indent}"""']


def render(text, module):
    tree = ast.parse(text)
    lines = text.splitlines()
    edits = []
    for node, doc in runtime_docs(tree, module):
        first = node.body[0]
        if first.lineno == node.lineno:
            raise SystemExit(f"{STUB}: {node.name}: put the body on its own line")
        indent = " " * first.col_offset
        keep = [s for s in node.body if not (isinstance(s, ast.Expr) and isinstance(s.value, ast.Constant))]
        new = quoted(doc, indent)
        if not keep:  # a body of `...` or a docstring alone: the docstring is the body
            edits.append((first.lineno - 1, node.body[-1].end_lineno, new))
        else:
            start = min([first.lineno] + [d.lineno for d in getattr(first, "decorator_list", [])]) - 1
            end = first.end_lineno if ast.get_docstring(node) is not None else start
            edits.append((start, end, new))
    for start, end, new in sorted(edits, reverse=True):
        lines[start:end] = new
    return "\n".join(lines) + "\n"


def main():
    from hylc import _hylc

    text = STUB.read_text()
    new = render(text, _hylc)
    if "--check" in sys.argv:
        sys.exit(0 if new == text else 1)
    STUB.write_text(new)


if __name__ == "__main__":
    main()
