#!/usr/bin/env python3
"""Lists C++ functions longer than --max-function lines and source files longer than --max-file
lines (the project's limits: 80 and 500, docs/DEVELOPING.md), outside test files.

    scripts/longfn.py [--root DIR] [--all] [--check] [--allow FILE] [PATHS...]

Without PATHS it reads modules/, pipeline/ and apps/ below --root (default: the repository).
Test files (a `test/` or `tests/` folder, or a name ending in `_test.cpp`) are left out unless
--all is given. A function's length runs from the first line of its head (return type, name,
parameters) to its closing brace; lambdas and local classes count inside their function. The
scan strips comments, string and character literals (raw strings too) and preprocessor lines,
then follows braces: a `{` opens a function body when the text before it at namespace or class
scope carries a parameter list and no `=` (so aggregate initialisers, enums, classes and
namespaces are told apart; member initialiser lists `: a_(x), b_{y}` are skipped).

--check compares the findings with the allow-list (default scripts/longfn_allow.txt; lines
`path:function  reason` or `path  reason` for a file, `#` comments) and exits 1 when something is
over a limit and not listed, or when a listed entry is no longer over (the list must stay exact).
Output: one line per finding, `path:line: function NAME is N lines (> 80)` or
`path: file is N lines (> 500)`; with --check, `allowed` or `NOT ALLOWED` after each, then a
summary line.
"""
import argparse
import os
import re
import sys

SOURCE_EXT = (".cpp", ".cc", ".cxx", ".h", ".hpp")
DEFAULT_DIRS = ("modules", "pipeline", "apps")
CONTROL = {"if", "for", "while", "switch", "catch", "do", "else", "try", "return", "sizeof", "decltype"}


TOKENS = re.compile(
    r"""(?P<raw>R"(?P<delim>[^()\\\s"]{0,16})\((?:.|\n)*?\)(?P=delim)")
      |(?P<line>//[^\n]*)
      |(?P<block>/\*(?:.|\n)*?\*/)
      |(?P<str>"(?:\\.|[^"\\\n])*")
      |(?P<chr>'(?:\\.|[^'\\\n])*')
      |(?P<pp>^[ \t]*\#(?:\\\n|[^\n])*)""",
    re.M | re.X,
)


def strip_code(text):
    """Comments, literals and preprocessor lines blanked; newlines kept so line numbers hold."""
    def blank(m):
        kept = "\n" * m.group(0).count("\n")
        if m.group("raw") or m.group("str"):
            return '""' + kept
        if m.group("chr"):
            return "''" + kept
        return " " + kept
    return TOKENS.sub(blank, text)


def top_level(head):
    """The head with everything inside (), <> of templates left out only for (): depth-0 text."""
    depth, keep = 0, []
    for ch in head:
        if ch == "(":
            depth += 1
            if depth == 1:
                keep.append("(")
            continue
        if ch == ")":
            depth -= 1
            if depth == 0:
                keep.append(")")
            continue
        if depth == 0:
            keep.append(ch)
    return "".join(keep)


def function_name(head):
    flat = top_level(head)
    k = flat.find("(")
    if k < 0:
        return None
    m = re.search(r"((?:[A-Za-z_~][A-Za-z0-9_]*\s*(?:<[^()]*?>)?\s*::\s*)*(?:operator\s*[^\s(]+|~?[A-Za-z_][A-Za-z0-9_]*))\s*$", flat[:k])
    return re.sub(r"\s+", "", m.group(1)) if m else None


def classify(head):
    """'namespace' | 'class' | 'function' | 'init' (aggregate / brace initialiser) for a `{`."""
    h = " ".join(head.split())
    h = re.sub(r"^(template\s*<.*?>\s*)+", "", h)
    if re.match(r"^(inline\s+)?namespace\b", h) or re.match(r'^extern\s*""', h):
        return "namespace"
    flat = top_level(h)
    if "operator" not in flat and re.search(r"(?<![=!<>+\-*/%&|^])=(?!=)", flat):
        return "init"
    if re.search(r"\b(class|struct|union|enum)\b", flat.split("(")[0]) and "(" not in flat.split(":")[0]:
        return "class"
    first = re.match(r"[A-Za-z_]+", h)
    if first and first.group(0) in CONTROL:
        return "init"
    if "(" in flat and function_name(h):
        return "function"
    return "init"


def find_functions(code):
    """[(name, first_line, last_line)] of outermost function definitions (1-based lines)."""
    found = []
    stack = []  # block kinds at namespace/class scope
    head_start = 0
    i, n = 0, len(code)
    while i < n:
        c = code[i]
        if c in ";}":
            if c == "}" and stack:
                stack.pop()
            head_start = i + 1
            i += 1
            continue
        if c != "{":
            i += 1
            continue
        head = code[head_start:i]
        kind = classify(head)
        flat = " ".join(top_level(head).split())
        ctor_init = kind == "function" and re.search(r"\)\s*(noexcept\s*)?:", flat) and re.search(r"[A-Za-z0-9_>]\s*$", head)
        if kind in ("namespace", "class"):
            stack.append(kind)
            head_start = i + 1
            i += 1
            continue
        if kind == "init" or ctor_init:
            i = match_brace(code, i) + 1  # a brace initialiser: part of the head or a statement
            continue
        end = match_brace(code, i)
        access = re.match(r"\s*((public|private|protected)\s*:(?!:))?\s*", head)
        start = head_start + access.end()
        first_line = code.count("\n", 0, start) + 1
        last_line = code.count("\n", 0, end) + 1
        found.append((function_name(head) or "?", first_line, last_line))
        i = end + 1
        head_start = i
    return found


def match_brace(code, i):
    depth = 0
    for j in range(i, len(code)):
        if code[j] == "{":
            depth += 1
        elif code[j] == "}":
            depth -= 1
            if depth == 0:
                return j
    return len(code) - 1


def is_test_file(rel):
    parts = rel.replace("\\", "/").split("/")
    return "test" in parts[:-1] or "tests" in parts[:-1] or parts[-1].endswith("_test.cpp")


def source_files(root, paths, include_tests):
    targets = paths or [os.path.join(root, d) for d in DEFAULT_DIRS]
    for t in targets:
        if os.path.isfile(t):
            yield t
            continue
        for dirpath, dirnames, filenames in os.walk(t):
            dirnames[:] = sorted(d for d in dirnames if d not in ("build", ".git"))
            for f in sorted(filenames):
                path = os.path.join(dirpath, f)
                rel = os.path.relpath(path, root)
                if f.endswith(SOURCE_EXT) and (include_tests or not is_test_file(rel)):
                    yield path


def findings(root, paths, include_tests, max_function, max_file):
    out = []
    for path in source_files(root, paths, include_tests):
        rel = os.path.relpath(path, root).replace("\\", "/")
        with open(path, encoding="utf-8", errors="replace") as fh:
            text = fh.read()
        lines = text.count("\n") + (0 if text.endswith("\n") or not text else 1)
        if lines > max_file:
            out.append((rel, None, 0, lines, f"{rel}: file is {lines} lines (> {max_file})"))
        for name, first, last in find_functions(strip_code(text)):
            length = last - first + 1
            if length > max_function:
                out.append((rel, name, first, length,
                            f"{rel}:{first}: function {name} is {length} lines (> {max_function})"))
    return out


def read_allow(path):
    allow = {}
    if not os.path.exists(path):
        return allow
    with open(path, encoding="utf-8") as fh:
        for raw in fh:
            line = raw.split("#", 1)[0].strip()
            if not line:
                continue
            key, _, reason = line.partition(" ")
            if not reason.strip():
                raise SystemExit(f"longfn: error: {path}: entry '{key}' has no reason")
            allow[key] = reason.strip()
    return allow


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("paths", nargs="*")
    ap.add_argument("--root", default=os.path.dirname(here))
    ap.add_argument("--all", action="store_true", help="include test files")
    ap.add_argument("--check", action="store_true", help="fail on findings not in the allow-list")
    ap.add_argument("--allow", default=os.path.join(here, "longfn_allow.txt"))
    ap.add_argument("--max-function", type=int, default=80)
    ap.add_argument("--max-file", type=int, default=500)
    args = ap.parse_args()
    root = os.path.abspath(args.root)
    result = findings(root, [os.path.abspath(p) for p in args.paths], args.all, args.max_function, args.max_file)
    if not args.check:
        for f in result:
            print(f[4])
        print(f"{len(result)} over the limits")
        return 0
    allow = read_allow(args.allow)
    used, bad = set(), 0
    for rel, name, _, _, text in result:
        key = f"{rel}:{name}" if name else rel
        if key in allow:
            used.add(key)
            print(f"{text}  allowed: {allow[key]}")
        else:
            bad += 1
            print(f"{text}  NOT ALLOWED")
    stale = sorted(set(allow) - used)
    for key in stale:
        print(f"{key}: listed in {os.path.relpath(args.allow, root)} but no longer over the limits: remove it")
    print(f"{len(result)} over the limits, {len(result) - bad} allowed, {bad} not allowed, {len(stale)} stale entries")
    return 1 if bad or stale else 0


if __name__ == "__main__":
    sys.exit(main())
