#!/usr/bin/env python3
"""Writes a copy of the recipe op table (baker/recipe/recipe_ops.c) with one more op: its
declaration and its line at the end of the table, the two edits an op needs there.
usage: add_op.py TABLE.c OP_NAME OUT.c"""
import sys

table, name, out = sys.argv[1:4]
text = open(table).read()
decl = "extern const recipe_op recipe_op_%s;\n" % name
end = text.index("};", text.index("recipe_ops[] = {"))
text = text[:end] + "    &recipe_op_%s,\n" % name + text[end:]
first = text.index("\nextern ") + 1
text = text[:first] + decl + text[first:]
open(out, "w").write(text)
