#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The README as a newcomer reads it: it starts with the two commands (the demo, every test); its
first clients are the example programs the tests build and run (each code block a slice of
examples/cpp/first_client.cpp or examples/python/first_client.py, line for line); its index names
every document in docs/ and nothing that is not there; and it stays short (150 lines at most).
Prints what does not hold. Usage: readme.py SOURCE_DIR"""
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1])
text = (root / "README.md").read_text(encoding="utf-8")
lines = text.splitlines()
bad = []
blocks = re.findall(r"^```(\w*)\n(.*?)^```", text, flags=re.S | re.M)
if not blocks or blocks[0][0] != "sh" or [x.split()[0] for x in blocks[0][1].splitlines()] != ["./deploy/run.sh", "./deploy/test.sh"]:
    bad.append("the README does not start with the two commands ./deploy/run.sh and ./deploy/test.sh")
if text.find("```") > text.find("\n## "):
    bad.append("the two commands are not the README's first block")
examples = {"cpp": root / "examples/cpp/first_client.cpp", "python": root / "examples/python/first_client.py"}
for language, body in blocks[1:]:
    if language not in examples:
        continue
    source = examples[language].read_text(encoding="utf-8").splitlines()
    shown = body.splitlines()
    if not any(source[i:i + len(shown)] == shown for i in range(len(source))):
        bad.append(f"the README's {language} block is not a slice of {examples[language].relative_to(root)} (copy it again)")
for language, path in examples.items():
    if f"```{language}\n" not in text:
        bad.append(f"the README shows no {language} client ({path.relative_to(root)})")
named = set(re.findall(r"`docs/([A-Z][A-Z-]*\.md)`", text))
present = {p.name for p in (root / "docs").glob("*.md")}
bad += [f"docs/{n} is not in the README's index of documents" for n in sorted(present - named)]
bad += [f"the README names docs/{n}, which does not exist" for n in sorted(named - present)]
if len(lines) > 150:
    bad.append(f"the README has {len(lines)} lines (150 at most: the rest belongs in docs/)")
if bad:
    print("\n".join(bad))
    sys.exit(1)
print(f"readme: {len(lines)} lines, the two commands first, {len(blocks) - 1} code blocks checked against the examples, {len(present)} documents indexed")
