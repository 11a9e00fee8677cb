#!/usr/bin/env python3
"""Lists C++ functions whose body spans more than --max-lines lines; exits 1 when there are any.

    check_function_size.py [--max-lines N] [--list] PATH...

PATH: .cpp/.hpp/.h files or folders (searched recursively). A function's length is counted as
clang-tidy's readability-function-size counts it (LineThreshold): the line of its body's closing
brace minus the line of its opening brace, comments and blank lines included. Lambdas and local
classes count towards the function they sit in. --list prints every function with its length
(path:line: name lines) instead of checking. Exit codes: 0 none over, 1 some over, 2 bad usage.

A small parser, not a compiler: comments, string and character literals (raw strings too) and
preprocessor lines are blanked first, then braces are matched. A brace at namespace or class scope
opens a function body when the text before it since the last ';', '{' or '}' has a parameter
list and is no class, struct, union, enum, namespace or '= {' initializer.
"""

import argparse
import os
import re
import sys

SOURCE_SUFFIXES = (".cpp", ".cc", ".hpp", ".h")


def strip_non_code(text):
    """Comments, literals and preprocessor lines replaced by spaces; newlines kept."""
    out = []
    i, n = 0, len(text)
    at_line_start = True
    while i < n:
        c = text[i]
        if at_line_start and c == "#":  # a directive, with its backslash continuations
            j = i
            while j < n and text[j] != "\n":
                if text[j] == "\\" and j + 1 < n and text[j + 1] == "\n":
                    j += 2
                    continue
                j += 1
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
            continue
        if c == "\n":
            at_line_start = True
            out.append(c)
            i += 1
            continue
        if not c.isspace():
            at_line_start = False
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
        elif c == "R" and text.startswith('R"', i) and (i == 0 or not is_ident(text[i - 1])):
            m = re.match(r'R"([^()\\\s]{0,16})\(', text[i:])
            if not m:
                out.append(c)
                i += 1
                continue
            close = ")" + m.group(1) + '"'
            j = text.find(close, i + m.end())
            j = n if j < 0 else j + len(close)
        elif c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum():  # digit separator: 1'000
                out.append(c)
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
        else:
            out.append(c)
            i += 1
            continue
        out.append(re.sub(r"[^\n]", " ", text[i:j]))
        i = j
    return "".join(out)


def is_ident(c):
    return c.isalnum() or c == "_"


def depth0_paren(header):
    """Index of the first '(' outside template angle brackets, or -1."""
    angle = 0
    for k, c in enumerate(header):
        if c == "<":
            angle += 1
        elif c == ">" and angle > 0:
            angle -= 1
        elif c == "(" and angle == 0:
            return k
    return -1


def classify(header):
    """What a '{' at namespace or class scope opens: namespace, class, function or other."""
    h = " ".join(header.split())
    h = re.sub(r"^template\s*<.*?>\s*(?=[A-Za-z_])", "", h)  # one template head, non-nested
    if re.match(r"(inline\s+)?namespace\b", h) or re.match(r"extern\s*$", h):
        return "namespace", None
    before_paren = h if depth0_paren(h) < 0 else h[: depth0_paren(h)]
    if re.search(r"\b(class|struct|union|enum)\b", before_paren):
        return "class", None
    operator = re.search(r"\boperator\s*(\(\)|[^\s(]+)", h)  # operator=, operator()
    named = h if not operator else h[: operator.start()] + "operator" + h[operator.end() :]
    p = depth0_paren(named)
    if p < 0 or "=" in named[:p]:
        return "other", None
    name = re.findall(r"[~A-Za-z_][\w:~]*", named[:p])
    name = name[-1] if name else "?"
    if operator and name.endswith("operator"):
        name += operator.group(1)
    return "function", name


def is_member_init(header):
    """A '{' after `header` brace-initializes a member in a constructor's initializer list."""
    h = header.rstrip()
    return bool(h) and is_ident(h[-1]) and re.search(r"\)\s*:(?!:)", h) is not None


def functions(text):
    """(name, line of the opening brace, body lines) of every function defined in `text`."""
    code = strip_non_code(text)
    found = []
    stack = []  # (kind, name, open line) per open brace
    header_start = 0
    line = 1
    for i, c in enumerate(code):
        if c == "\n":
            line += 1
        elif c == "{":
            if any(kind in ("function", "other") for kind, _, _ in stack):
                kind, name = "other", None
            else:
                kind, name = classify(code[header_start:i])
                if kind == "function" and is_member_init(code[header_start:i]):
                    kind = "member_init"  # the header goes on after its closing brace
            stack.append((kind, name, line))
            if kind != "member_init":
                header_start = i + 1
        elif c == "}":
            if stack:
                kind, name, open_line = stack.pop()
                if kind == "function":
                    found.append((name, open_line, line - open_line))
                if kind == "member_init":
                    continue
            header_start = i + 1
        elif c == ";":
            header_start = i + 1
    return found


def source_files(paths):
    for path in paths:
        if os.path.isdir(path):
            for root, dirs, files in os.walk(path):
                dirs.sort()
                for f in sorted(files):
                    if f.endswith(SOURCE_SUFFIXES):
                        yield os.path.join(root, f)
        else:
            yield path


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--max-lines", type=int, default=80)
    parser.add_argument("--list", action="store_true", help="print every function's length")
    parser.add_argument("paths", nargs="+")
    args = parser.parse_args()  # exits 2 on a usage error
    if args.max_lines < 1:
        parser.error("--max-lines must be >= 1")
    for path in args.paths:
        if not os.path.exists(path):
            parser.error(f"no such file or folder: {path}")
    over = []
    count = 0
    for path in source_files(args.paths):
        with open(path, encoding="utf-8") as f:
            text = f.read()
        for name, line, lines in functions(text):
            count += 1
            if args.list:
                print(f"{path}:{line}: {name} {lines}")
            elif lines > args.max_lines:
                over.append(f"{path}:{line}: {name} is {lines} lines (max {args.max_lines})")
    if args.list:
        return 0
    for entry in over:
        print(entry)
    if over:
        print(f"{len(over)} of {count} functions over {args.max_lines} lines: split them into "
              "named stages (STYLE.md)", file=sys.stderr)
        return 1
    print(f"all {count} functions within {args.max_lines} lines")
    return 0


if __name__ == "__main__":
    sys.exit(main())
