#!/usr/bin/env python3
"""The house limits on source size: no file over 800 lines and no function over
150 lines in the production code (src/, pipeline/, exporters/, apps/).

Functions are found by their braces: a block whose header (the text since the
previous ';', '{' or '}') looks like a function definition - a parameter list
and no control keyword - at namespace or class level; lambdas and local
classes count towards the function that holds them. Comments, strings and
preprocessor lines are blanked first. A function's length is from its header's
first line to its closing brace.

Files named in EXEMPT (generated or table data) are skipped, each with its
reason. scripts/limits-known.txt lists what is over its limit today and is
being split, each with its size: such an item may shrink but not grow, and a
listed item back within its limit must leave the list. Exit 1, naming every
file and function over its limit that the list does not allow (and every
stale entry); --report prints the longest ones either way.

Usage: scripts/check_limits.py [--report] [--no-known] [ROOT]
"""
import os
import re
import sys

MAX_FILE_LINES = 800
MAX_FUNCTION_LINES = 150
FOLDERS = ("src", "pipeline", "exporters", "apps")
EXTENSIONS = (".cpp", ".hpp", ".h", ".cc")
# Generated or table data: path -> why it may be long.
EXEMPT = {}
KNOWN = "scripts/limits-known.txt"

CONTROL = re.compile(r"^\s*(if|for|while|switch|catch|do|else|try|return)\b|^\s*(else\s+if)\b")
CONTAINER = re.compile(r"\b(namespace|class|struct|union|enum)\b[^()]*$")


def blank(text):
    """Comments, string and char literals and preprocessor lines as spaces (newlines kept)."""
    out = []
    i, n = 0, len(text)
    line_start = True
    while i < n:
        c = text[i]
        if line_start and c == "#":
            j = i
            while j < n and text[j] != "\n":
                if text[j] == "\\" and j + 1 < n and text[j + 1] == "\n":
                    out.append(" \n")
                    j += 2
                    continue
                out.append(" ")
                j += 1
            i = j
            continue
        if c == "\n":
            line_start = True
            out.append(c)
            i += 1
            continue
        if not c.isspace():
            line_start = False
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("".join(ch if ch == "\n" else " " for ch in text[i:j]))
            i = j
        elif c == 'R' and text.startswith('R"', i):
            m = re.match(r'R"([^(]*)\(', text[i:])
            end = text.find(")" + m.group(1) + '"', i) if m else -1
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append("".join(ch if ch == "\n" else " " for ch in text[i:j]))
            i = j
        elif c in "\"'":
            if c == "'" and i > 0 and (text[i - 1].isalnum()):  # digit separator 1'000
                out.append(" ")
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(" " * (j - i))
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(text):
    """(name, first line, last line) of each function definition in the text."""
    code = blank(text)
    found = []
    stack = []  # per open brace: 'container', 'function' or 'block'
    header_start = 0
    line_of = [0] * (len(code) + 1)
    line = 1
    for k, ch in enumerate(code):
        line_of[k] = line
        if ch == "\n":
            line += 1
    for k, ch in enumerate(code):
        if ch == "{":
            header = code[header_start:k]
            inside_function = "function" in stack
            kind = "block"
            if not inside_function:
                h = header.strip()
                if CONTAINER.search(h) or h.startswith("extern") or h == "":
                    kind = "container" if h != "" or not stack or stack[-1] == "container" else "block"
                    if h.endswith("=") or re.search(r"=\s*$", h):
                        kind = "block"
                elif ")" in h and not CONTROL.match(h) and not h.endswith("="):
                    kind = "function"
                    name = re.search(r"([~\w:]+(?:operator\S*)?)\s*\(", h)
                    first = line_of[header_start + (len(header) - len(header.lstrip()))]
                    stack.append(kind)
                    found.append([name.group(1) if name else h[:40], first, None, len(stack)])
                    header_start = k + 1
                    continue
            stack.append(kind)
            header_start = k + 1
        elif ch == "}":
            if stack:
                kind = stack.pop()
                if kind == "function":
                    for f in reversed(found):
                        if f[2] is None and f[3] == len(stack) + 1:
                            f[2] = line_of[k]
                            break
            header_start = k + 1
        elif ch == ";":
            header_start = k + 1
        elif ch == ":" and not inside_function_kind(stack):
            # access specifiers ("public:") end a header; "::" does not
            if (k + 1 < len(code) and code[k + 1] == ":") or (k > 0 and code[k - 1] == ":"):
                continue
            tail = code[header_start:k].strip()
            if tail in ("public", "private", "protected"):
                header_start = k + 1
    return [(f[0], f[1], f[2]) for f in found if f[2] is not None]


def read_known(path):
    """path:function or path -> the lines it may have (# comments)."""
    known = {}
    if not os.path.exists(path):
        return known
    with open(path, encoding="utf-8") as f:
        for line in f:
            line = line.split("#", 1)[0].strip()
            if line:
                name, lines = line.rsplit(None, 1)
                known[name] = int(lines)
    return known


def inside_function_kind(stack):
    return "function" in stack


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    report = "--report" in sys.argv
    root = args[0] if args else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    long_files, long_functions = [], []
    for folder in FOLDERS:
        for dirpath, _, names in os.walk(os.path.join(root, folder)):
            for name in sorted(names):
                if not name.endswith(EXTENSIONS):
                    continue
                path = os.path.join(dirpath, name)
                rel = os.path.relpath(path, root)
                if rel in EXEMPT:
                    continue
                with open(path, encoding="utf-8", errors="replace") as f:
                    text = f.read()
                lines = text.count("\n")
                long_files.append((lines, rel))
                for fn, first, last in functions(text):
                    long_functions.append((last - first + 1, f"{rel}:{first}", fn))
    long_files.sort(reverse=True)
    long_functions.sort(reverse=True)
    known = {} if "--no-known" in sys.argv else read_known(os.path.join(root, KNOWN))
    over = {rel: lines for lines, rel in long_files if lines > MAX_FILE_LINES}
    for lines, where, fn in long_functions:
        if lines > MAX_FUNCTION_LINES:
            over[where.split(":")[0] + ":" + fn] = max(lines, over.get(where.split(":")[0] + ":" + fn, 0))
    stale = sorted(k for k in known if k not in over)
    grown = sorted(k for k in over if k in known and over[k] > known[k])
    bad_files = [f for f in long_files if f[0] > MAX_FILE_LINES and f[1] not in known]
    bad_functions = [f for f in long_functions if f[0] > MAX_FUNCTION_LINES and
                     f[1].split(":")[0] + ":" + f[2] not in known]
    if report:
        print("longest files:")
        for lines, rel in long_files[:10]:
            print(f"  {lines:5d} {rel}")
        print("longest functions:")
        for lines, where, fn in long_functions[:15]:
            print(f"  {lines:5d} {where} {fn}")
    for lines, rel in bad_files:
        print(f"{rel}: {lines} lines (the limit is {MAX_FILE_LINES})")
    for lines, where, fn in bad_functions:
        print(f"{where}: function {fn} is {lines} lines (the limit is {MAX_FUNCTION_LINES})")
    for k in grown:
        print(f"{k}: {over[k]} lines, more than the {known[k]} {KNOWN} allows (split it instead)")
    for k in stale:
        print(f"{k}: within its limit now; remove it from {KNOWN}")
    if bad_files or bad_functions or grown or stale:
        return 1
    print(f"every file within {MAX_FILE_LINES} lines and every function within "
          f"{MAX_FUNCTION_LINES} lines in {', '.join(FOLDERS)}"
          + (f", but for the {len(known)} being split ({KNOWN})" if known else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
