#!/usr/bin/env python3
"""The longest files and functions of a C++ tree (the house's size figures, docs/developing.md).

    bench/longest.py [DIR ...] [--top N]        (default: tools/core, top 10)

A function is a brace block opened at namespace level (column 0 or inside `namespace`), whose
header line holds a `(`: free functions, member functions defined out of class and lambdas are
counted with their enclosing definition. Lines are counted from the header to the closing brace.
Comments and strings are stripped before braces are matched, so a brace in either does not count.
Prints `lines path` for files and `lines path:line name` for functions, longest first.
"""
import os
import re
import sys


def Strip(text):
    """The text with comments, string and char literals blanked (newlines kept)."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i)); i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j])); i = j
        elif text.startswith('R"', i):
            m = re.match(r'R"([^(]*)\(', text[i:])
            end = text.find(")" + m.group(1) + '"', i) if m else -1
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j])); i = j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(" " * (j + 1 - i)); i = j + 1
        else:
            out.append(c); i += 1
    return "".join(out)


def Functions(path):
    lines = Strip(open(path, encoding="utf-8").read()).split("\n")
    depth, scopes, found = 0, [], []  # scopes: (kind, start line, name) per open brace
    for no, line in enumerate(lines, 1):
        for k, c in enumerate(line):
            if c == "{":
                at_top = all(s[0] == "namespace" for s in scopes)
                head = " ".join(lines[max(0, no - 4):no - 1] + [line[:k]])
                if re.search(r"\bnamespace\b[^;{}]*$", head):
                    scopes.append(("namespace", no, ""))
                elif at_top and re.search(r"\)[^;{}()]*$", head) and not re.search(r"\b(struct|class|enum|union)\b[^;{}]*$", head):
                    m = re.search(r"([\w:~<>]+)\s*\([^;{}]*\)[^;{}()]*$", head)
                    scopes.append(("function", no, m.group(1) if m else "?"))
                else:
                    scopes.append(("block", no, ""))
            elif c == "}" and scopes:
                kind, start, name = scopes.pop()
                if kind == "function":
                    found.append((no - start + 1, start, name))
    return found


def main():
    args, top = [], 10
    argv = sys.argv[1:]
    while argv:
        a = argv.pop(0)
        if a == "--top":
            top = int(argv.pop(0))
        else:
            args.append(a)
    files = []
    for d in args or ["tools/core"]:
        for folder, _, names in os.walk(d):
            files += [os.path.join(folder, f) for f in names if f.endswith((".h", ".cpp"))]
    sizes = sorted(((sum(1 for _ in open(f, encoding="utf-8")), f) for f in files), reverse=True)
    funcs = sorted(((n, f, s, name) for f in files for n, s, name in Functions(f)), reverse=True)
    print(f"files ({len(files)}), longest first:")
    for n, f in sizes[:top]:
        print(f"{n:6d} {f}")
    print(f"functions ({len(funcs)}), longest first:")
    for n, f, s, name in funcs[:top]:
        print(f"{n:6d} {f}:{s} {name}")


if __name__ == "__main__":
    main()
