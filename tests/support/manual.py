"""The SPACAR95 manual's §5, transcribed once for the tests (from the manual, not from spacar's
code): the element types of §5.1 with their node kinds and parameter counts and the deformation
counts of formulation.md §4, the other keywords of §5.2–5.6, and the slider-crank example of §5.7:
its input is examples/slidercrank.dat (the manual's file, unchanged) and is read as ``INPUT``; its
printed state after 5 s is ``OUTPUT``, tests/data/manual_output.dat (verbatim), parsed by
``parse_dump``.
"""
from __future__ import annotations

import re

from support.paths import DATA

OUTPUT = DATA / "manual_output.dat"

XY, BETA, XYZ, LAMBDA = "XY", "BETA", "XYZ", "LAMBDA"

# type: (node kinds in order, number of deformations, (min, max) numbers on the definition line
# after the nodes) -- manual §5.1 (nodes, parameters), formulation §4 (kinds, deformations).
ELEMENTS = {
    "BEAM": ((XYZ, LAMBDA, XYZ, LAMBDA), 6, (3, 3)),      # x y z
    "BEAMNL": ((XYZ, LAMBDA, XYZ, LAMBDA), 6, (3, 3)),    # x y z
    "TRUSS": ((XYZ, XYZ), 1, (0, 0)),
    "HINGE": ((LAMBDA, LAMBDA), 3, (3, 3)),               # axis x y z
    "BEARING": ((XYZ, LAMBDA, XYZ, LAMBDA), 6, (3, 3)),   # axis x y z
    "SURFACE": ((XYZ,), 1, (10, 10)),                     # c1..c10
    "L2MIN1": ((LAMBDA,), 1, (0, 0)),
    "PLBEAM": ((XY, BETA, XY, BETA), 3, (0, 0)),
    "PLBEAMNL": ((XY, BETA, XY, BETA), 3, (0, 0)),
    "PLHINGE": ((BETA, BETA), 1, (0, 0)),
    "PLTRUSS": ((XY, XY), 1, (0, 0)),
    "PLBELT": ((XY, BETA, XY, BETA), 1, (2, 2)),          # r1 r2
    "PLBEAR": ((XY, BETA, XY, BETA), 3, (0, 0)),
    "PLWHEEL": ((XY, BETA, BETA), 2, (3, 3)),             # r x y
}

# Every other keyword of §5.2-5.6.
KEYWORDS = [
    "X", "XY", "BETA", "XYZ", "LAMBDA",                                        # §5.2 nodes
    "FIX", "INPUTX", "DYNX", "RLSE", "INPUTE", "DYNE", "LINE", "ENHC",         # §5.3 boundary conditions
    "XD", "XDD", "E", "ED", "EDD", "TIME", "DIR", "LGEOMY", "LENGTHO",         # §5.4 initial values
    "MASS", "EMASS", "ESTIFF", "EDAMPP", "FORCE", "TORQUEL",                   # §5.5 dynamic properties
    "TIMESTEP", "HMAX", "MAXITERAT", "EPSKIN", "EPSINT", "EPSIND", "FORCEMODE",  # §5.6 settings
    "ANIMATE", "MATASC", "JOBID", "RESTART", "EOF", "END",
]

# The example input of §5.7, as (keyword, values); the manual writes "Timestep".
INPUT = [
    ("PLBEAM", (1, 1, 2, 3, 4)),
    ("PLBEAM", (2, 3, 5, 6, 7)),
    ("PLBEAM", (3, 6, 7, 8, 9)),
    ("FIX", (1,)),
    ("FIX", (8, 2)),
    ("X", (3, 0.15, 0.0)),
    ("X", (6, 0.30, 0.0)),
    ("X", (8, 0.45, 0.0)),
    ("INPUTX", (2, 1)),
    ("DYNE", (2, 2)),
    ("DYNE", (2, 3)),
    ("DYNE", (3, 2)),
    ("DYNE", (3, 3)),
    ("TIMESTEP", (100, 5.0)),
    ("MASS", (8, 0.033375)),
    ("EMASS", (1, 0.2225)),
    ("EMASS", (2, 0.2225)),
    ("EMASS", (3, 0.2225)),
    ("ESTIFF", (2, 0.0, 0.0012723)),
    ("ESTIFF", (3, 0.0, 0.0012723)),
    ("INPUTX", (2, 1)),
    ("XD", (2, 1, 1.5)),
]

_INT = re.compile(r"^[+-]?\d+$")


def parse_line(line):
    """(keyword, integer fields, real fields as (value, text)) of one dump line."""
    tokens = line.split()
    ints, reals = [], []
    for tok in tokens[1:]:
        if _INT.match(tok) and not reals:
            ints.append(int(tok))
        else:
            reals.append((float(tok), tok))
    return tokens[0].upper(), tuple(ints), reals


def parse_dump(text):
    """The non-comment lines of a dump, parsed."""
    return [parse_line(line) for line in text.splitlines() if line.strip() and not line.startswith("*")]


def values(dump, keyword):
    """{(n, i): value} of XY/BETA (per component) or E/ED/EDD lines of a parsed dump."""
    out = {}
    for kw, ints, reals in dump:
        if kw != keyword:
            continue
        if keyword in ("XY", "BETA"):
            for i, (v, _) in enumerate(reals, start=1):
                out[(ints[0], i)] = v
        else:
            out[(ints[0], ints[1])] = reals[0][0]
    return out


def printed_state():
    """The manual's printed state after 5 s, parsed (tests/data/manual_output.dat)."""
    return parse_dump(OUTPUT.read_text())
