"""Replaces the lines between "<!-- NAME:begin -->" and "<!-- NAME:end -->" of a
results page with a generated table: the benchmark scripts' --output.

    python3 bench/replace_section.py PAGE NAME TABLE_FILE
"""
import sys

path, name, table = sys.argv[1], sys.argv[2], open(sys.argv[3]).read()
text = open(path).read()
begin, end = f"<!-- {name}:begin -->", f"<!-- {name}:end -->"
b, e = text.index(begin), text.index(end)
open(path, "w").write(text[: b + len(begin)] + "\n" + table + text[e:])
