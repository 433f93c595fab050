"""Every file the project's comments and docs cite is a file of the repository.

A clone holds only the repository, so a citation must name a file in it or a source by title and
section (docs/design.md, "References"); never a path outside it such as `../shared/...`.
Scanned: tools/, tests/, bench/, docs/, scripts/, cmake/ and the top-level CMakeLists.txt and
README.md; in code only the comments (C++ `//` and `/* */`, `#` in Python, shell and CMake, and
Python docstrings), in Markdown the whole text. Checked:
- no `../shared` and no `shared/{seeds,notes,data}/` (outside the repository);
- every `<name>.md` resolves: with a folder, from the repository root (or, in docs/, from docs/);
  without one, to docs/<name>.md, the top level or a file of that name somewhere in the repository;
- every path that starts with a top-level folder of the repository (atmospheres/, tools/, tests/,
  bench/, scripts/, docs/, cmake/, particles/, ocio/, viewer/; not clouds/, which is also a folder
  of the bake's outputs) exists; a path written as a pattern (followed by `*`, `{`, `<` or `$`) or
  inside another repository (after `owner/name `, e.g. `ovidiopr/scattnlay tests/test_py.py`) is not
  checked;
- every core path `<module>/<file>.h|.cpp` (the modules of tools/core) exists in tools/core;
- every section cited as `docs/<doc>.md "Name"` (or `<doc>.md, "Name"`, for a doc of docs/ or the
  top-level README.md) is a heading or a bold label (`**Name...**`) of that doc, or the start of one.
Offenders are printed as `file:line: citation`.

Runs with the standard library only: `python3 tests/data/test_citations.py` or through ctest
(label `data`).
"""
import io
import os
import re
import tokenize
import unittest

ROOT = os.environ.get("SKYBAKE_SOURCE_DIR") or os.path.normpath(os.path.join(os.path.dirname(__file__), "..", ".."))
SCANNED_DIRS = ["tools", "tests", "bench", "docs", "scripts", "cmake"]
SCANNED_FILES = ["CMakeLists.txt", "README.md"]
SKIPPED_DIRS = {"golden", "regressions", "corpus", "node_modules", "images", "__pycache__"}
C_LIKE = {".h", ".hpp", ".cpp", ".cc", ".c", ".js", ".mjs", ".glsl", ".frag", ".vert"}
HASH_COMMENTS = {".cmake", ".sh", ".yaml", ".yml", ".txt"}
TOP_DIRS = "atmospheres|tools|tests|bench|scripts|docs|cmake|particles|ocio|viewer"
CORE_MODULES = "atmosphere|color|fog|io|lut|noise|optics|spectrum|transport"

OUTSIDE = re.compile(r"\.\./shared\b|(?<![\w.])shared/(?:seeds|notes|data)/")
MD_FILE = re.compile(r"(?<![\w./-])((?:[\w.-]+/)*[\w-]+\.md)\b")
REPO_PATH = re.compile(r"(?<![\w./-])((?:" + TOP_DIRS + r")/[\w./-]*[\w])")
CORE_PATH = re.compile(r"(?<![\w./-])((?:" + CORE_MODULES + r")/[\w-]+\.(?:h|cpp))\b")
SECTION = re.compile(r"(?<![\w./-])(?:docs/)?([\w-]+)\.md`?,? (?:\"([^\"\n]{1,100})\"|“([^”\n]{1,100})”)")
PATTERN_CHARS = "*{<$["
# Known offenders, as (file, start of the offence); each must still offend (delete its line when fixed).
KNOWN = set()
OTHER_REPO = re.compile(r"(?<![\w./-])[\w.-]+/[\w.-]+ $")


def ScannedFiles():
    for name in SCANNED_FILES:
        path = os.path.join(ROOT, name)
        if os.path.isfile(path):
            yield path
    for top in SCANNED_DIRS:
        for folder, dirs, files in os.walk(os.path.join(ROOT, top)):
            dirs[:] = sorted(d for d in dirs if d not in SKIPPED_DIRS and not d.startswith("."))
            for f in sorted(files):
                yield os.path.join(folder, f)


def IsPython(path, text):
    return path.endswith(".py") or text.startswith("#!/usr/bin/env python")


def CitingText(path, text):
    """(line number, text) pieces that can cite: comments of code, the whole of Markdown."""
    ext = os.path.splitext(path)[1]
    if ext == ".md":
        return list(enumerate(text.splitlines(), 1))
    if IsPython(path, text):
        pieces, previous = [], None
        try:
            for tok in tokenize.generate_tokens(io.StringIO(text).readline):
                # A docstring is a string that is a statement of its own (not a value in code).
                docstring = tok.type == tokenize.STRING and previous in (None, tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT)
                if tok.type == tokenize.COMMENT or docstring:
                    for i, line in enumerate(tok.string.splitlines()):
                        pieces.append((tok.start[0] + i, line))
                if tok.type not in (tokenize.NL, tokenize.COMMENT):
                    previous = tok.type
        except (tokenize.TokenError, SyntaxError):
            pass
        return pieces
    if ext in C_LIKE:
        pieces, in_block = [], False
        for n, line in enumerate(text.splitlines(), 1):
            if in_block:
                end = line.find("*/")
                pieces.append((n, line if end < 0 else line[:end]))
                in_block = end < 0
                continue
            at = line.find("//")
            block = line.find("/*")
            if block >= 0 and (at < 0 or block < at):
                end = line.find("*/", block + 2)
                pieces.append((n, line[block + 2:] if end < 0 else line[block + 2:end]))
                in_block = end < 0
            elif at >= 0 and not line[:at].rstrip().endswith(":"):  # not a URL's "//"
                pieces.append((n, line[at + 2:]))
        return pieces
    if ext in HASH_COMMENTS or os.path.basename(path) == "CMakeLists.txt" or text.startswith("#!"):
        return [(n, line[line.find("#") + 1:]) for n, line in enumerate(text.splitlines(), 1) if "#" in line]
    return []


def DocLabels(doc):
    with open(os.path.join(ROOT, doc), encoding="utf-8") as f:
        text = f.read()
    labels = {h.strip().strip("`") for h in re.findall(r"^#+\s+(.*)$", text, re.M)}
    labels |= {b.strip() for b in re.findall(r"\*\*([^*\n]+)\*\*", text)}
    return labels


def FileNamesInRepo():
    names = set()
    for folder, dirs, files in os.walk(ROOT):
        dirs[:] = [d for d in dirs if not d.startswith(".") and d != "build"]
        names.update(files)
    return names


class Citations(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.names = FileNamesInRepo()
        docs = [os.path.join("docs", f) for f in sorted(os.listdir(os.path.join(ROOT, "docs"))) if f.endswith(".md")]
        cls.labels = {doc: DocLabels(doc) for doc in docs + ["README.md"]}

    def Exists(self, rel):
        return os.path.exists(os.path.join(ROOT, rel.rstrip(".")))

    def Offenders(self):
        offenders = []
        for path in ScannedFiles():
            try:
                with open(path, encoding="utf-8") as f:
                    text = f.read()
            except (UnicodeDecodeError, OSError):
                continue
            rel = os.path.relpath(path, ROOT)
            if rel == os.path.relpath(__file__, ROOT):
                continue  # this file names the patterns it looks for
            in_docs = rel.startswith("docs" + os.sep)
            for n, piece in CitingText(path, text):
                def Offend(what):
                    offenders.append(f"{rel}:{n}: {what}")
                for m in OUTSIDE.finditer(piece):
                    Offend(f"outside the repository: {piece[m.start():m.start() + 40].strip()}")
                for m in MD_FILE.finditer(piece):
                    md = m.group(1)
                    if "/" in md:
                        if not (self.Exists(md) or (in_docs and self.Exists(os.path.join("docs", md)))) and not md.startswith("../"):
                            Offend(md)
                    elif not (self.Exists(os.path.join("docs", md)) or md in self.names):
                        Offend(md)
                for m in REPO_PATH.finditer(piece):
                    after = piece[m.end():m.end() + 1]
                    if (after and after in PATTERN_CHARS) or OTHER_REPO.search(piece[:m.start()]):
                        continue
                    if not self.Exists(m.group(1)):
                        Offend(m.group(1))
                for m in CORE_PATH.finditer(piece):
                    if not self.Exists(os.path.join("tools", "core", m.group(1))):
                        Offend(m.group(1))
                for m in SECTION.finditer(piece):
                    doc = "README.md" if m.group(1) == "README" else f"docs/{m.group(1)}.md"
                    section = m.group(2) or m.group(3)
                    if doc not in self.labels:
                        continue  # a doc that does not exist is reported above
                    if not any(label == section or label.startswith(section) for label in self.labels[doc]):
                        Offend(f'{doc} "{section}" (no such heading or bold label)')
        return offenders

    def test_every_citation_resolves(self):
        offenders, known_seen = [], set()
        for o in self.Offenders():
            known = [k for k in KNOWN if o.startswith(k[0] + ":") and o.split(": ", 1)[1].startswith(k[1])]
            if known:
                known_seen.update(known)
            else:
                offenders.append(o)
        for o in offenders:
            print(o)
        self.assertEqual(offenders, [], f"{len(offenders)} citations do not resolve (listed above)")
        self.assertEqual(sorted(KNOWN - known_seen), [], "fixed: delete these from KNOWN")


if __name__ == "__main__":
    unittest.main()
