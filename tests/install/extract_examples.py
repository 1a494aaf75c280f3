#!/usr/bin/python3
"""Writes every fenced block of LANG in the given Markdown files to OUT_DIR/<doc>_<n>.<ext>.

Usage: extract_examples.py LANG EXT OUT_DIR DOC.md...
"""
import os
import re
import sys

lang, ext, out = sys.argv[1], sys.argv[2], sys.argv[3]
os.makedirs(out, exist_ok=True)
for doc in sys.argv[4:]:
    stem = os.path.splitext(os.path.basename(doc))[0]
    blocks = re.findall(r"^```%s\n(.*?)^```$" % re.escape(lang), open(doc).read(), re.S | re.M)
    for n, code in enumerate(blocks, 1):
        with open(os.path.join(out, f"{stem}_{n}.{ext}"), "w") as f:
            f.write(code)
