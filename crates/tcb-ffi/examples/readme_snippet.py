#!/usr/bin/env python3
"""Write the README's C snippet (section "From C and C++") as a C program:
its #include lines, then the rest as the body of main. CI compiles and runs
it, so the lines a C user copies stay true.
Usage: readme_snippet.py README.md OUT.c  (stdlib only)"""
import sys

readme, out = sys.argv[1], sys.argv[2]
text = open(readme).read()
section = text[text.index("## From C and C++"):]
start = section.index("```c\n") + len("```c\n")
body = section[start:section.index("```", start)].splitlines()
includes = [l for l in body if l.startswith("#include")]
code = [l for l in body if not l.startswith("#include")]
with open(out, "w") as f:
    f.write("#include <stdio.h>\n#include <stdlib.h>\n")
    f.write("\n".join(includes) + "\n\nint main(void) {\n")
    f.write("\n".join("    " + l if l else l for l in code) + "\n    return 0;\n}\n")
