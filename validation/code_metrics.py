#!/usr/bin/env python3
"""Structure metrics of the crate's source tree, for a refactoring's before/after report.

usage: python3 validation/code_metrics.py [--rev REV] [--json]
       python3 validation/code_metrics.py --max-lines N

With --max-lines N (the check `.ci/run` makes), the script lists every `fn` item with a body in src/ and
python/src/ (methods, nested fns and test fns included) longer than N lines, as `path:line: item (L lines)`, and
exits 1 if there is any, 0 otherwise. The report below is not printed then.

With --rev, the tree is read from git at REV (`git ls-tree -r --name-only REV src`, `git show REV:path`; nothing is
checked out); without it, the working tree. Only `src/` is read, so `tests/`, `benches/` and `proptests/` never count.
Everything inside an item marked `#[cfg(test)]` (in practice the `mod tests { ... }` blocks; also `mod tests;` files
and `#![cfg(test)]` files) is left out of every count.

The source is tokenised by a small Rust lexer (comments, nested block comments, strings, byte strings, raw strings
r"..."/r#"..."#, char literals versus lifetimes and labels, raw identifiers), so braces, keywords and patterns inside
comments or string literals never count. Printed:

1. the ten longest `fn` items with a body (methods, trait default methods and nested fns included, library and
   bin), counted from the line of the `fn` keyword to the line of the closing brace, both included; and how many
   exceed 120 lines;
2. lines per file in src/bin/ (newline-terminated lines, as `wc -l`);
3. library functions (src/ without src/bin) whose return type contains `Result<..., String>` (the last generic
   argument of a `Result<...>` in the return type is exactly `String`), and the "String error sites":
   `Err(format!(`, `.map_err(|x| x.to_string())`, `.map_err(|x| format!(`, `Err("...".into())` (also
   `.to_string()`, `.to_owned()`, `String::from("...")`), and `ShellError(` constructions (not its definition), in
   the library and in src/bin separately, plus the number of `.map_err` calls in src/bin. The closure parameter
   may be any single identifier, `_` included;
4. the dependency graph between the top-level modules declared in src/lib.rs: module A depends on B when a
   file of A names `crate::B` (or `crate::{B...}`, or reaches the crate root with `super::` and names B); its
   cycles (strongly connected components and the simple cycles in them);
5. the hand-written error types: `enum`/`struct` items whose name ends in `Error`, in src/.
"""
import argparse
import json
import os
import re
import subprocess
import sys
from collections import defaultdict

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LONG = 120
TOP_N = 10


# ------------------------------------------------------------------------------------------------------------------
# reading the tree


def git(*args):
    return subprocess.run(["git", "-C", ROOT, *args], check=True, capture_output=True).stdout


def read_tree(rev):
    """{path relative to the repository: text} for every .rs file under src/."""
    files = {}
    if rev is None:
        for dirpath, dirnames, filenames in os.walk(os.path.join(ROOT, "src")):
            dirnames.sort()
            for f in sorted(filenames):
                if f.endswith(".rs"):
                    full = os.path.join(dirpath, f)
                    rel = os.path.relpath(full, ROOT).replace(os.sep, "/")
                    with open(full, encoding="utf-8") as fh:
                        files[rel] = fh.read()
    else:
        names = git("ls-tree", "-r", "--name-only", rev, "src").decode().split("\n")
        for p in names:
            if p.endswith(".rs"):
                files[p] = git("show", f"{rev}:{p}").decode("utf-8")
    return files


# ------------------------------------------------------------------------------------------------------------------
# lexer


class Tok:
    __slots__ = ("kind", "text", "line")

    def __init__(self, kind, text, line):
        self.kind = kind  # id, punct, str, char, life, num
        self.text = text
        self.line = line

    def __repr__(self):
        return f"{self.kind}:{self.text!r}@{self.line}"


RAW_STR = re.compile(r'(?:br|cr|r)(#*)"')
PREFIX_STR = re.compile(r'[bc]"')
RAW_IDENT = re.compile(r"r#([^\W\d]\w*)")
IDENT = re.compile(r"[^\W\d]\w*")
NUMBER = re.compile(
    r"(?:0x[0-9a-fA-F_]+|0o[0-7_]+|0b[01_]+|\d[\d_]*(?:\.\d[\d_]*)?(?:[eE][+-]?[\d_]+)?)(?:[^\W\d]\w*)?"
)
LIFETIME = re.compile(r"'[^\W\d]\w*")
TWO_CHAR = {"::", "->", "=>"}


def _skip_quoted(text, j):
    """j is just past an opening '"'; returns the index just past the closing '"' (escapes honoured)."""
    n = len(text)
    while j < n:
        c = text[j]
        if c == "\\":
            j += 2
        elif c == '"':
            return j + 1
        else:
            j += 1
    return n


def lex(text):
    toks = []
    i, n, line = 0, len(text), 1
    while i < n:
        c = text[i]
        if c == "\n":
            line += 1
            i += 1
            continue
        if c.isspace():
            i += 1
            continue
        if c == "/" and i + 1 < n and text[i + 1] == "/":
            j = text.find("\n", i)
            i = n if j < 0 else j
            continue
        if c == "/" and i + 1 < n and text[i + 1] == "*":
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth += 1
                    j += 2
                elif text.startswith("*/", j):
                    depth -= 1
                    j += 2
                else:
                    j += 1
            line += text.count("\n", i, j)
            i = j
            continue
        if c in "rbc":
            m = RAW_STR.match(text, i)
            if m:
                close = '"' + m.group(1)
                j = text.find(close, m.end())
                j = n if j < 0 else j + len(close)
                toks.append(Tok("str", text[i:j], line))
                line += text.count("\n", i, j)
                i = j
                continue
            m = PREFIX_STR.match(text, i)
            if m:
                j = _skip_quoted(text, m.end())
                toks.append(Tok("str", text[i:j], line))
                line += text.count("\n", i, j)
                i = j
                continue
            if c == "b" and text.startswith("b'", i):
                j = _char_end(text, i + 1)
                toks.append(Tok("char", text[i:j], line))
                i = j
                continue
            m = RAW_IDENT.match(text, i)
            if m:
                toks.append(Tok("id", m.group(1), line))
                i = m.end()
                continue
        if c == '"':
            j = _skip_quoted(text, i + 1)
            toks.append(Tok("str", text[i:j], line))
            line += text.count("\n", i, j)
            i = j
            continue
        if c == "'":
            if i + 1 < n and text[i + 1] == "\\" or i + 2 < n and text[i + 2] == "'" and text[i + 1] != "\n":
                j = _char_end(text, i)
                toks.append(Tok("char", text[i:j], line))
                i = j
                continue
            m = LIFETIME.match(text, i)
            if m:
                toks.append(Tok("life", m.group(0), line))
                i = m.end()
                continue
            toks.append(Tok("punct", c, line))
            i += 1
            continue
        m = IDENT.match(text, i)
        if m:
            toks.append(Tok("id", m.group(0), line))
            i = m.end()
            continue
        if c.isdigit():
            m = NUMBER.match(text, i)
            toks.append(Tok("num", m.group(0), line))
            i = m.end()
            continue
        two = text[i : i + 2]
        if two in TWO_CHAR:
            toks.append(Tok("punct", two, line))
            i += 2
            continue
        toks.append(Tok("punct", c, line))
        i += 1
    return toks


def _char_end(text, i):
    """text[i] is the opening quote of a char literal; returns the index just past the closing quote."""
    n = len(text)
    j = i + 1
    if j < n and text[j] == "\\":
        j += 2  # the escaped character (\\' or \\\\ or the letter of \\n, \\x.., \\u{..})
    else:
        j += 1
    k = text.find("'", j)
    return n if k < 0 else k + 1


# ------------------------------------------------------------------------------------------------------------------
# per-file analysis

OPEN = {"(": ")", "[": "]", "{": "}"}
CLOSE = {")": "(", "]": "[", "}": "{"}


def match_brackets(toks, path, warnings):
    match = {}
    stack = []
    for i, t in enumerate(toks):
        if t.kind != "punct":
            continue
        if t.text in OPEN:
            stack.append(i)
        elif t.text in CLOSE:
            if not stack or toks[stack[-1]].text != CLOSE[t.text]:
                warnings.append(f"{path}:{t.line}: unbalanced {t.text!r}")
                continue
            j = stack.pop()
            match[i], match[j] = j, i
    for j in stack:
        warnings.append(f"{path}:{toks[j].line}: unclosed {toks[j].text!r}")
    return match


def is_p(tok, text):
    return tok is not None and tok.kind == "punct" and tok.text == text


def is_id(tok, text=None):
    return tok is not None and tok.kind == "id" and (text is None or tok.text == text)


def skip_to_body(toks, match, k):
    """From k, skip () and [] groups; return the index of the first '{' or ';' (or len(toks))."""
    n = len(toks)
    while k < n:
        t = toks[k]
        if t.kind == "punct":
            if t.text in ("(", "[") and k in match:
                k = match[k] + 1
                continue
            if t.text in ("{", ";"):
                return k
        k += 1
    return n


def module_info(path):
    """(is_bin, module path parts, depth below the crate root, directory holding its child module files)."""
    if path.startswith("python/src/"):  # the Python module's crate: no bin, its own root
        rel = path[len("python/src/") :]
        parts = [] if rel == "lib.rs" else rel[: -len(".rs")].split("/")
        if parts and parts[-1] == "mod":
            parts = parts[:-1]
        return False, parts, len(parts), None
    rel = path[len("src/") :]
    if rel.startswith("bin/"):
        parts = rel[len("bin/") : -len(".rs")].split("/")
        if parts[-1] in ("main", "mod") and len(parts) > 1:
            parts = parts[:-1]
        return True, parts, len(parts) - 1, None
    if rel == "lib.rs":
        return False, [], 0, "src"
    parts = rel[: -len(".rs")].split("/")
    own_dir = "src/" + "/".join(parts[:-1]) if parts[-1] == "mod" else "src/" + "/".join(parts)
    if parts[-1] == "mod":
        parts = parts[:-1]
    return False, parts, len(parts), own_dir


def test_attr(toks, match, i):
    """If toks[i] starts an attribute, return (end index, inner?, is cfg(test)); else None."""
    if not is_p(toks[i], "#"):
        return None
    j = i + 1
    inner = False
    if j < len(toks) and is_p(toks[j], "!"):
        inner = True
        j += 1
    if j >= len(toks) or not is_p(toks[j], "[") or j not in match:
        return None
    end = match[j]
    body = toks[j + 1 : end]
    cfg = (
        len(body) >= 2
        and is_id(body[0], "cfg")
        and is_p(body[1], "(")
        and any(is_id(t, "test") for t in body)
        and not any(is_id(t, "not") for t in body)
    )
    return end, inner, cfg


def analyse_file(path, text, warnings):
    toks = lex(text)
    match = match_brackets(toks, path, warnings)
    n = len(toks)
    excluded = [False] * n
    test_mod_files = []  # names of `#[cfg(test)] mod x;`
    whole_file_test = False

    i = 0
    while i < n:
        a = test_attr(toks, match, i)
        if a is None:
            i += 1
            continue
        end, inner, cfg = a
        if not cfg:
            i = end + 1
            continue
        if inner:
            whole_file_test = True
            break
        k = end + 1
        while k < n:  # further attributes on the same item
            b = test_attr(toks, match, k)
            if b is None or b[1]:
                break
            k = b[0] + 1
        item_start = k
        k = skip_to_body(toks, match, k)
        item_end = match.get(k, k) if k < n and is_p(toks[k], "{") else k
        item_end = min(item_end, n - 1)
        for m in range(i, item_end + 1):
            excluded[m] = True
        item = toks[item_start : item_end + 1]
        for q in range(len(item) - 2):
            if is_id(item[q], "mod") and is_id(item[q + 1]) and is_p(item[q + 2], ";"):
                test_mod_files.append(item[q + 1].text)
        i = item_end + 1

    is_bin, mod_parts, depth, _ = module_info(path)
    functions = []
    pending = {}  # index of a '{' -> context
    stack = []  # contexts of the open braces
    mod_depth = [0] * n  # depth below the crate root at each token
    inline_mods = 0
    for i, t in enumerate(toks):
        mod_depth[i] = depth + inline_mods
        if t.kind == "id":
            nxt = toks[i + 1] if i + 1 < n else None
            prev = toks[i - 1] if i > 0 else None
            if t.text == "fn" and is_id(nxt):
                k = skip_to_body(toks, match, i + 2)
                quals = [c["name"] for c in stack if c and c["kind"] in ("fn", "impl", "trait", "mod")]
                f = {
                    "file": path,
                    "line": t.line,
                    "vis": visibility(toks, match, i),
                    "nested": any(c and c["kind"] == "fn" for c in stack),
                    "name": nxt.text,
                    "qual": "::".join(mod_parts + quals + [nxt.text]),
                    "sig": toks[i + 2 : k],
                    "bin": is_bin,
                    "test": excluded[i],
                    "end": None,
                    "lines": None,
                }
                functions.append(f)
                if k < n and is_p(toks[k], "{"):
                    pending[k] = {"kind": "fn", "name": nxt.text, "fn": f}
            elif t.text == "impl" and (prev is None or prev.kind == "punct" and prev.text in "{};]" or
                                       is_id(prev, "unsafe") or is_id(prev, "default")):
                k = skip_to_body(toks, match, i + 1)
                if k < n and is_p(toks[k], "{"):
                    pending[k] = {"kind": "impl", "name": impl_name(toks[i + 1 : k])}
            elif t.text in ("trait", "mod") and is_id(nxt):
                k = skip_to_body(toks, match, i + 2)
                if k < n and is_p(toks[k], "{"):
                    pending[k] = {"kind": t.text, "name": nxt.text}
        elif t.kind == "punct":
            if t.text == "{":
                ctx = pending.pop(i, None)
                stack.append(ctx)
                if ctx and ctx["kind"] == "mod":
                    inline_mods += 1
            elif t.text == "}" and i in match:
                ctx = stack.pop() if stack else None
                if ctx and ctx["kind"] == "mod":
                    inline_mods -= 1
                if ctx and ctx["kind"] == "fn":
                    f = ctx["fn"]
                    f["end"] = t.line
                    f["lines"] = t.line - f["line"] + 1

    return {
        "path": path,
        "toks": toks,
        "match": match,
        "excluded": excluded,
        "mod_depth": mod_depth,
        "functions": functions,
        "test_mod_files": test_mod_files,
        "whole_file_test": whole_file_test,
        "bin": is_bin,
        "mod_parts": mod_parts,
        "lines": text.count("\n") + (0 if text.endswith("\n") or not text else 1),
    }


def visibility(toks, match, i):
    """`pub`, `pub(...)` or `private` for the `fn` keyword at i."""
    k = i - 1
    while k >= 0 and (toks[k].kind == "str" or toks[k].kind == "id" and
                      toks[k].text in ("const", "async", "unsafe", "extern")):
        k -= 1
    if k >= 0 and is_id(toks[k], "pub"):
        return "pub"
    if k >= 0 and is_p(toks[k], ")") and k in match and match[k] > 0 and is_id(toks[match[k] - 1], "pub"):
        return "pub(" + " ".join(t.text for t in toks[match[k] + 1 : k]) + ")"
    return "private"


def impl_name(toks):
    """The self type's name of an impl header (tokens after `impl` up to the body)."""
    k = 0
    if k < len(toks) and is_p(toks[k], "<"):  # impl<...>
        depth = 0
        while k < len(toks):
            if is_p(toks[k], "<"):
                depth += 1
            elif is_p(toks[k], ">"):
                depth -= 1
                if depth == 0:
                    k += 1
                    break
            k += 1
    rest = toks[k:]
    depth = 0
    for q, t in enumerate(rest):  # `Trait for Type`: the type follows `for` at angle depth 0
        if is_p(t, "<"):
            depth += 1
        elif is_p(t, ">"):
            depth -= 1
        elif depth == 0 and is_id(t, "for"):
            rest = rest[q + 1 :]
            break
        elif depth == 0 and is_id(t, "where"):
            rest = rest[:q]
            break
    name = None
    for t in rest:  # last identifier of the leading path
        if t.kind == "id" and t.text not in ("dyn", "mut", "const"):
            name = t.text
        elif is_p(t, "::") or is_p(t, "&") or t.kind == "life":
            continue
        elif name is not None:
            break
    return name or "?"


# ------------------------------------------------------------------------------------------------------------------
# 3. String errors


def returns_result_string(sig):
    """Whether the return type (after `->` outside parentheses) contains a `Result<..., String>`."""
    k, n = 0, len(sig)
    depth = 0
    arrow = None
    while k < n:
        t = sig[k]
        if t.kind == "punct" and t.text in "([":
            depth += 1
        elif t.kind == "punct" and t.text in ")]":
            depth -= 1
        elif depth == 0 and is_p(t, "->"):
            arrow = k
            break
        k += 1
    if arrow is None:
        return False
    ret = sig[arrow + 1 :]
    angle = 0
    for q, t in enumerate(ret):  # stop at a where clause
        if is_p(t, "<"):
            angle += 1
        elif is_p(t, ">"):
            angle -= 1
        elif angle == 0 and is_id(t, "where"):
            ret = ret[:q]
            break
    for q, t in enumerate(ret):
        if is_id(t, "Result") and q + 1 < len(ret) and is_p(ret[q + 1], "<"):
            args = generic_args(ret, q + 1)
            if args and [x.text for x in args[-1]] in (["String"], ["std", "::", "string", "::", "String"]):
                return True
    return False


def generic_args(toks, lt):
    """toks[lt] is '<'; split the generic arguments at top-level commas."""
    args, cur = [], []
    angle = paren = 0
    for t in toks[lt:]:
        if is_p(t, "<"):
            angle += 1
            if angle == 1:
                continue
        elif is_p(t, ">"):
            angle -= 1
            if angle == 0:
                args.append(cur)
                return args
        elif t.kind == "punct" and t.text in "([":
            paren += 1
        elif t.kind == "punct" and t.text in ")]":
            paren -= 1
        elif is_p(t, ",") and angle == 1 and paren == 0:
            args.append(cur)
            cur = []
            continue
        cur.append(t)
    return None


ID, STR = object(), object()  # wildcards in patterns
V1 = ("var", 1)

# (key, label, list of token patterns); a pattern element is a string (exact token text), ID (any identifier,
# `_` included), STR (a string literal) or V1 (an identifier, bound at its first occurrence and equal after)
PATTERNS = [
    ("err_format", "`Err(format!(`", [["Err", "(", "format", "!", "("]]),
    ("map_err_to_string", "`.map_err(|x| x.to_string())`",
     [[".", "map_err", "(", "|", V1, "|", V1, ".", "to_string", "(", ")", ")"]]),
    ("map_err_format", "`.map_err(|x| format!(`", [[".", "map_err", "(", "|", ID, "|", "format", "!", "("]]),
    ("err_literal", "`Err(\"...\".into() / .to_string() / .to_owned() / String::from(\"...\"))`",
     [["Err", "(", STR, ".", m, "(", ")", ")"] for m in ("into", "to_string", "to_owned")]
     + [["Err", "(", "String", "::", "from", "(", STR, ")", ")"]]),
    ("shell_error", "`ShellError(` constructions", [["ShellError", "("]]),
]


def match_at(toks, i, pat):
    bound = {}
    for q, p in enumerate(pat):
        if i + q >= len(toks):
            return False
        t = toks[i + q]
        if p is ID:
            if t.kind != "id":
                return False
        elif p is STR:
            if t.kind != "str":
                return False
        elif isinstance(p, tuple):
            if t.kind != "id":
                return False
            if p in bound and bound[p] != t.text:
                return False
            bound[p] = t.text
        elif t.text != p or t.kind in ("str", "char"):
            return False
    return True


def string_error_sites(info):
    toks, excl = info["toks"], info["excluded"]
    counts = defaultdict(int)
    sites = defaultdict(list)
    map_err = 0
    for i, t in enumerate(toks):
        if excl[i]:
            continue
        if is_p(t, ".") and is_id(toks[i + 1] if i + 1 < len(toks) else None, "map_err"):
            map_err += 1
        for key, _, pats in PATTERNS:
            for pat in pats:
                if match_at(toks, i, pat):
                    if key == "shell_error" and i > 0 and is_id(toks[i - 1], "struct"):
                        continue  # the definition
                    counts[key] += 1
                    sites[key].append(f"{info['path']}:{t.line}")
                    break
    return counts, sites, map_err


# ------------------------------------------------------------------------------------------------------------------
# 4. module graph


def top_modules(lib):
    mods = []
    toks, excl = lib["toks"], lib["excluded"]
    depth = 0
    for i, t in enumerate(toks):
        if is_p(t, "{"):
            depth += 1
        elif is_p(t, "}"):
            depth -= 1
        elif depth == 0 and not excl[i] and is_id(t, "mod") and i + 2 < len(toks) and is_id(toks[i + 1]) \
                and is_p(toks[i + 2], ";"):
            mods.append(toks[i + 1].text)
    return mods


def root_names(toks, match, k):
    """toks[k] follows `crate::` (or the `super::` chain reaching the root): the top-level names it reaches."""
    if k >= len(toks):
        return []
    t = toks[k]
    if t.kind == "id":
        return [(t.text, t.line)]
    if is_p(t, "{") and k in match:
        names = []
        end = match[k]
        q = k + 1
        expect = True
        while q < end:
            u = toks[q]
            if expect and u.kind == "id":
                names.append((u.text, u.line))
            expect = False
            if u.kind == "punct" and u.text in "([{" and q in match:
                q = match[q] + 1
                continue
            if is_p(u, ","):
                expect = True
            q += 1
        return names
    return []


def module_edges(infos, mods):
    modset = set(mods)
    edges = defaultdict(lambda: defaultdict(list))  # a -> b -> [file:line]
    for info in infos:
        if info["bin"] or not info["mod_parts"]:
            continue
        a = info["mod_parts"][0]
        if a not in modset:
            continue
        toks, match, excl, mdep = info["toks"], info["match"], info["excluded"], info["mod_depth"]
        n = len(toks)
        for i, t in enumerate(toks):
            if excl[i] or t.kind != "id":
                continue
            prev = toks[i - 1] if i > 0 else None
            reached = None
            if t.text == "crate" and i + 1 < n and is_p(toks[i + 1], "::"):
                reached = i + 2
            elif t.text == "super" and not is_p(prev, "::"):
                k, ups = i, 0
                while k + 1 < n and is_id(toks[k], "super") and is_p(toks[k + 1], "::"):
                    ups += 1
                    k += 2
                if ups and ups == mdep[i]:
                    reached = k
            if reached is None:
                continue
            for name, line in root_names(toks, match, reached):
                if name in modset and name != a:
                    edges[a][name].append(f"{info['path']}:{line}")
    return edges


def sccs(nodes, adj):
    index, low, on, stack, out = {}, {}, set(), [], []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(adj.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            out.append(sorted(comp, key=nodes.index))

    for v in nodes:
        if v not in index:
            visit(v)
    return out


def simple_cycles(nodes, adj, limit=200):
    """Every simple cycle once, starting at its earliest node in `nodes` order (capped at `limit`)."""
    order = {v: k for k, v in enumerate(nodes)}
    cycles = []

    def dfs(start, v, path, seen):
        for w in sorted(adj.get(v, ()), key=order.get):
            if len(cycles) >= limit:
                return
            if w == start:
                cycles.append(path + [start])
            elif order[w] > order[start] and w not in seen:
                seen.add(w)
                dfs(start, w, path + [w], seen)
                seen.discard(w)

    for s in nodes:
        dfs(s, s, [s], {s})
    return cycles


# ------------------------------------------------------------------------------------------------------------------
# putting it together


def measure(rev):
    files = read_tree(rev)
    warnings = []
    infos = {p: analyse_file(p, t, warnings) for p, t in sorted(files.items())}

    # files of out-of-line `#[cfg(test)] mod x;` and `#![cfg(test)]` files
    test_files = {p for p, info in infos.items() if info["whole_file_test"]}
    for p, info in infos.items():
        if info["bin"]:
            continue
        own_dir = module_info(p)[3]
        for name in info["test_mod_files"]:
            for cand in (f"{own_dir}/{name}.rs", f"{own_dir}/{name}/mod.rs"):
                if cand in infos:
                    test_files.add(cand)
    for p in list(test_files):  # and everything below them
        d = p[: -len("/mod.rs")] if p.endswith("/mod.rs") else p[: -len(".rs")]
        test_files.update(q for q in infos if q.startswith(d + "/"))
    for p in test_files:
        infos[p]["excluded"] = [True] * len(infos[p]["toks"])
        for f in infos[p]["functions"]:
            f["test"] = True
    measured = [info for p, info in infos.items() if p not in test_files]

    # 1. functions
    fns = [f for info in measured for f in info["functions"] if not f["test"] and f["lines"] is not None]
    fns.sort(key=lambda f: (-f["lines"], f["file"], f["line"]))
    longest = [{"file": f["file"], "line": f["line"], "end": f["end"], "name": f["name"], "item": f["qual"],
                "lines": f["lines"]} for f in fns[:TOP_N]]
    over = [f for f in fns if f["lines"] > LONG]

    # 2. src/bin
    bin_files = {p: infos[p]["lines"] for p in infos if infos[p]["bin"]}

    # 3. String errors
    lib_infos = [i for i in measured if not i["bin"]]
    bin_infos = [i for i in measured if i["bin"]]
    res_string = [{"file": f["file"], "line": f["line"], "item": f["qual"], "vis": f["vis"], "nested": f["nested"]}
                  for info in lib_infos for f in info["functions"]
                  if not f["test"] and returns_result_string(f["sig"])]

    def tally(group):
        counts, sites, map_err = defaultdict(int), defaultdict(list), 0
        for info in group:
            c, s, m = string_error_sites(info)
            for k, v in c.items():
                counts[k] += v
                sites[k] += s[k]
            map_err += m
        return {k: counts[k] for k, _, _ in PATTERNS}, dict(sites), map_err

    lib_counts, lib_sites, lib_map_err = tally(lib_infos)
    bin_counts, bin_sites, bin_map_err = tally(bin_infos)

    # 4. module graph
    mods = top_modules(infos["src/lib.rs"]) if "src/lib.rs" in infos else []
    edges = module_edges(measured, mods)
    adj = {a: set(bs) for a, bs in edges.items()}
    comps = [c for c in sccs(mods, adj) if len(c) > 1 or (c[0] in adj.get(c[0], ()))]
    cycles = simple_cycles(mods, adj)

    # 5. error types
    err_types = []
    for info in measured:
        toks, excl = info["toks"], info["excluded"]
        for i in range(len(toks) - 1):
            if not excl[i] and toks[i].kind == "id" and toks[i].text in ("enum", "struct") \
                    and is_id(toks[i + 1]) and toks[i + 1].text.endswith("Error"):
                err_types.append({"file": info["path"], "line": toks[i].line, "kind": toks[i].text,
                                  "name": toks[i + 1].text})

    head = git("rev-parse", "--short", rev or "HEAD").decode().strip()
    dirty = rev is None and bool(git("status", "--porcelain", "--", "src").strip())
    return {
        "tree": f"git {rev} ({head})" if rev else f"working tree (HEAD {head}{', src/ modified' if dirty else ''})",
        "files": len(infos),
        "test_files_excluded": sorted(test_files),
        "warnings": warnings,
        "functions": {
            "measured": len(fns),
            "measured_lib": sum(not f["bin"] for f in fns),
            "measured_bin": sum(f["bin"] for f in fns),
            "longest": longest,
            "over_limit": LONG,
            "over": len(over),
            "over_lib": sum(not f["bin"] for f in over),
            "over_bin": sum(f["bin"] for f in over),
            "over_list": [{"file": f["file"], "line": f["line"], "item": f["qual"], "lines": f["lines"]}
                          for f in over],
        },
        "bin_lines": {"total": sum(bin_files.values()), "files": bin_files},
        "string_errors": {
            "result_string_fns": len(res_string),
            "result_string_pub": sum(f["vis"] == "pub" for f in res_string),
            "result_string_nested": sum(f["nested"] for f in res_string),
            "result_string_list": res_string,
            "patterns": {k: label for k, label, _ in PATTERNS},
            "lib": {"counts": lib_counts, "total": sum(lib_counts.values()), "sites": lib_sites},
            "bin": {"counts": bin_counts, "total": sum(bin_counts.values()), "sites": bin_sites},
            "lib_map_err": lib_map_err,
            "bin_map_err": bin_map_err,
        },
        "modules": {
            "modules": mods,
            "imports": {a: sorted(edges.get(a, {}), key=mods.index) for a in mods},
            "edge_sites": {a: {b: s for b, s in bs.items()} for a, bs in edges.items()},
            "edges": sum(len(bs) for bs in edges.values()),
            "has_cycle": bool(comps),
            "strongly_connected": comps,
            "cycles": cycles,
        },
        "error_types": {"count": len(err_types), "list": err_types},
    }


def markdown(r):
    out = []
    w = out.append
    w(f"# Code metrics: {r['tree']}")
    w("")
    w(f"{r['files']} .rs files under src/; `#[cfg(test)]` items excluded"
      + (f" (and the test files {', '.join(r['test_files_excluded'])})" if r["test_files_excluded"] else "") + ".")
    for x in r["warnings"]:
        w(f"- warning: {x}")
    fn = r["functions"]
    w("")
    w(f"## 1. Longest functions ({fn['measured']} fns with a body: {fn['measured_lib']} library, "
      f"{fn['measured_bin']} bin)")
    w("")
    w("| # | lines | function | location |")
    w("|--:|--:|---|---|")
    for k, f in enumerate(fn["longest"], 1):
        loc = f"{f['file']}:{f['line']}"
        item = f["item"] if not f["file"].startswith("src/bin/") else "[bin] " + f["item"]
        w(f"| {k} | {f['lines']} | `{item}` | {loc} |")
    w("")
    w(f"Functions over {fn['over_limit']} lines: **{fn['over']}** ({fn['over_lib']} library, "
      f"{fn['over_bin']} bin).")
    b = r["bin_lines"]
    w("")
    w(f"## 2. src/bin: {b['total']} lines")
    w("")
    w("| file | lines |")
    w("|---|--:|")
    for p, n in sorted(b["files"].items(), key=lambda x: (-x[1], x[0])):
        w(f"| {p} | {n} |")
    w(f"| **total** | **{b['total']}** |")
    s = r["string_errors"]
    w("")
    w("## 3. String errors")
    w("")
    w(f"Library functions returning `Result<_, String>`: **{s['result_string_fns']}** "
      f"({s['result_string_pub']} `pub`, {s['result_string_fns'] - s['result_string_pub']} not; "
      f"{s['result_string_nested']} of them nested in another fn)")
    w("")
    for f in s["result_string_list"]:
        extra = ", ".join(x for x in (f["vis"] if f["vis"] != "pub" else "", "nested" if f["nested"] else "") if x)
        w(f"- `{f['item']}` ({f['file']}:{f['line']})" + (f" [{extra}]" if extra else ""))
    w("")
    w("| String error site | library | src/bin |")
    w("|---|--:|--:|")
    for k, label in s["patterns"].items():
        w(f"| {label.replace('|', chr(92) + '|')} | {s['lib']['counts'][k]} | {s['bin']['counts'][k]} |")
    w(f"| **total** | **{s['lib']['total']}** | **{s['bin']['total']}** |")
    w(f"| `.map_err(` calls (all) | {s['lib_map_err']} | {s['bin_map_err']} |")
    m = r["modules"]
    w("")
    w(f"## 4. Module dependency graph ({len(m['modules'])} top-level modules, {m['edges']} edges)")
    w("")
    w("| module | imports (`crate::X`) |")
    w("|---|---|")
    for a in m["modules"]:
        w(f"| {a} | {', '.join(m['imports'][a]) or '—'} |")
    w("")
    if not m["has_cycle"]:
        w("Cycles: **none** (the graph is acyclic).")
    else:
        w(f"Cycles: **yes**. Strongly connected components: "
          + "; ".join("{" + ", ".join(c) + "}" for c in m["strongly_connected"]) + ".")
        w("")
        w(f"Simple cycles ({len(m['cycles'])}{', capped' if len(m['cycles']) >= 200 else ''}):")
        w("")
        for c in m["cycles"]:
            w("- " + " → ".join(c))
        w("")
        w("Edges inside the cycles (first site):")
        w("")
        in_cycle = set()
        for c in m["cycles"]:
            in_cycle.update(zip(c, c[1:]))
        for a, bb in sorted(in_cycle, key=lambda e: (m["modules"].index(e[0]), m["modules"].index(e[1]))):
            sites = m["edge_sites"][a][bb]
            w(f"- {a} → {bb}: {sites[0]}" + (f" (+{len(sites) - 1} more)" if len(sites) > 1 else ""))
    e = r["error_types"]
    w("")
    w(f"## 5. Error types: {e['count']}")
    w("")
    for x in e["list"]:
        w(f"- `{x['kind']} {x['name']}` ({x['file']}:{x['line']})")
    return "\n".join(out)


def long_functions(max_lines):
    """Every `fn` with a body in src/ and python/src/ of the working tree (tests included) over max_lines lines."""
    found, warnings = [], []
    for top in ("src", "python/src"):
        for dirpath, dirnames, filenames in os.walk(os.path.join(ROOT, top)):
            dirnames.sort()
            for f in sorted(filenames):
                if not f.endswith(".rs"):
                    continue
                full = os.path.join(dirpath, f)
                rel = os.path.relpath(full, ROOT).replace(os.sep, "/")
                with open(full, encoding="utf-8") as fh:
                    info = analyse_file(rel, fh.read(), warnings)
                found += [fn for fn in info["functions"] if fn["lines"] is not None and fn["lines"] > max_lines]
    return found, warnings


def check_max_lines(max_lines):
    found, warnings = long_functions(max_lines)
    for x in warnings:
        print(f"warning: {x}", file=sys.stderr)
    for f in found:
        print(f"{f['file']}:{f['line']}: {f['qual']} ({f['lines']} lines)")
    if found:
        print(f"{len(found)} function(s) over {max_lines} lines: split them into helpers", file=sys.stderr)
        return 1
    print(f"no function over {max_lines} lines in src/ and python/src/")
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rev", help="read the tree at this git revision instead of the working tree")
    ap.add_argument("--json", action="store_true", help="print JSON instead of Markdown")
    ap.add_argument("--max-lines", type=int, metavar="N",
                    help="list the functions (tests included, src/ and python/src/) over N lines; exit 1 if any")
    args = ap.parse_args()
    if args.max_lines is not None:
        sys.exit(check_max_lines(args.max_lines))
    r = measure(args.rev)
    if args.json:
        json.dump(r, sys.stdout, indent=1, ensure_ascii=False)
        print()
    else:
        print(markdown(r))


if __name__ == "__main__":
    main()
