"""Fuzzing harness of spacar (issue #9): hypothesis strategies that generate hostile inputs, the
oracle that runs one of them, and the long campaign in worker processes.

What is generated (``cases()``):

- input texts: the manual's slider-crank with random edits (lines deleted, duplicated, swapped,
  tokens replaced by garbage, extreme numbers or other keywords); random models built from the
  element catalogue (planar and spatial, random classes, properties, initial values and
  settings, several blocks); soups of random keyword lines; chains of up to ``max_size``
  elements with element and node numbers up to 2^31 - 1; lines with extreme counts and
  tolerances (TIMESTEP 10^9, EPSINT 1e-300, HMAX 1e300, MAXITERAT 10^9, TIME 1e308, ...);
  random case, tabs, CR/LF, comments, NUL bytes;
- Python API programs: builder calls with wrong types and values (None, strings, bytes, lists,
  arrays, complex, Decimal, Fraction, bool, NaN, infinities, huge and negative integers, NumPy
  scalars), copy, pickle, summary, check, dump, simulate and linearize with odd arguments, result
  lookups, and spacar.sweep with odd parameters.

The oracle (``run_case``): reading, summary, check, the state dump (which must read back to the
same dump), pickling (which must give the same dump) and, for a fraction of the cases,
simulate (with a time limit; in the default run with at most 4 output intervals) and linearize.
Allowed outcomes: success, or a ``spacar.SpacarError``. A reader error must name the file. A
successful simulation must give finite results. Anything else — another exception type, a
non-finite result, a dump that does not read back — is a *finding* (``Finding``). Crashes and
hangs are caught by the campaign (worker processes, a heartbeat, the last case on disk) and, in
the default run, by a faulthandler watchdog that ends the process with a traceback.

The long campaign::

    python tests/support/fuzzing.py --cases 100000 --workers 2 --report fuzz-report.json

or ``pytest -m slow tests/io/test_fuzz.py``; see docs/robustness.md.
"""
from __future__ import annotations

import argparse
import faulthandler
import json
import math
import os
import pickle
import re
import signal
import subprocess
import sys
import tempfile
import time
import traceback
import warnings
from collections import Counter
from dataclasses import dataclass, field
from decimal import Decimal
from fractions import Fraction
from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, Phase, given, seed, settings
from hypothesis import strategies as st

import spacar
from spacar import SpacarError
from spacar._util import show
from spacar.keywords import INT, KEYWORDS

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = (ROOT / "examples" / "slidercrank.dat").read_text()
EXAMPLE_LINES = EXAMPLE.splitlines()

# Memory an analysis may use while fuzzing: the guard is exercised, the machine is spared.
FUZZ_MEMORY_LIMIT = 256 * 2**20
SIM_TIME_LIMIT = 2.0        # seconds per simulation (TimeLimitError beyond)
SLOW_CASE = 30.0            # seconds: a case slower than this is a finding
# Python's own arity errors of methods with fixed parameters (m.xd(1)) are not findings.
ARITY = re.compile(r"(missing \d+ required|takes \d+ positional|positional arguments? but \d+|"
                   r"got an unexpected keyword|takes from \d+ to \d+ positional|takes no arguments)")


class Finding(AssertionError):
    """A case that broke a rule of the oracle."""


# --- value pools --------------------------------------------------------------------------------

INT_TOKENS = ["0", "1", "2", "3", "4", "5", "8", "9", "-1", "-2", "10", "100", "1000", "1001", "2147483647",
              "-2147483648", "2147483648", "4294967297", "10000000", "10000001", "1000000000", "99999999999999999999",
              "1.", "1.0D0", "2e0", "+3", "-0"]
REAL_TOKENS = ["0", "-0", "0.", ".5", "1", "-1", "1e-300", "-1e-300", "5e-324", "2.2e-308", "1e300", "-1e300", "1e308",
               "1.7976931348623157e308", "1e309", "-1e309", "1e400", "nan", "NaN", "inf", "-inf", "Infinity", "1.0D-3",
               "2.5", "1e-16", "1e-9", "1e-15", "0.15", "0.3", "3.14159", "-2.5", "1e20", "1e-20", "0.5", "0.6", "0.8"]
GARBAGE_TOKENS = ["", "1e", "e1", "--1", "+-1", "0x10", "1_000", "\u0663", "*", "#", "END", "EOF", "\x00", "é", "1,5",
                  "(1)", "1/2", "1..2", ".", "-", "+", "D", "1d", "TRUE", "\t", "\x0c", "\u2028", "\U0001f600"]
PY_VALUES = [None, True, False, 0, 1, 2, 3, 8, -1, -(2**31), 2**31 - 1, 2**31, 10**400, 10**5000, 1.5, 0.15, -0.0,
             1e-300, 1e308, math.nan, math.inf, -math.inf, "1", "nan", b"1", [1], [1.0, 2.0], (1, 2), {}, set(),
             np.float32("nan"), np.float64(0.5), np.int64(3), np.int8(-1), np.bool_(True), np.array([1.0, 2.0]),
             np.array(1.0), np.array([]), np.float16(1e4), 1 + 2j, Decimal("1.5"), Decimal("NaN"), Fraction(1, 3),
             Fraction(10**400, 7), object(), print, Ellipsis, range(3)]


def _keyword_names():
    return sorted(KEYWORDS)


@st.composite
def tokens(draw, kind=None):
    choice = draw(st.integers(0, 9))
    if choice <= 4:
        if kind == INT or (kind is None and choice % 2 == 0):
            return draw(st.one_of(st.integers(-3, 30).map(str), st.sampled_from(INT_TOKENS)))
        return draw(st.one_of(st.sampled_from(REAL_TOKENS), st.floats(-10, 10, allow_nan=False).map(repr)))
    if choice <= 6:
        return draw(st.one_of(st.sampled_from(INT_TOKENS), st.sampled_from(REAL_TOKENS)))
    if choice == 7:
        return draw(st.floats(allow_nan=True, allow_infinity=True).map(repr))
    if choice == 8:
        return draw(st.sampled_from(GARBAGE_TOKENS + _keyword_names()))
    return draw(st.text(min_size=1, max_size=8))


@st.composite
def keyword_line(draw):
    """A line of a random keyword with roughly (sometimes exactly, sometimes not) its arguments."""
    kw = KEYWORDS[draw(st.sampled_from(_keyword_names()))]
    words = [draw(st.sampled_from([kw.name, kw.name.lower(), kw.name.title(), kw.name + "XYZ"[: draw(st.integers(0, 3))]]))]
    for p in kw.params:
        hi = min(p.count_max, p.count_min + 3)
        for _ in range(draw(st.integers(p.count_min, hi))):
            words.append(draw(tokens(p.kind)))
    if draw(st.integers(0, 5)) == 0:
        words.append(draw(tokens()))
    if draw(st.integers(0, 5)) == 0 and len(words) > 1:
        del words[draw(st.integers(1, len(words) - 1))]
    return " ".join(words)


EXTREME_LINES = ["TIMESTEP 1000000000 1", "TIMESTEP 10000000 5.0", "TIMESTEP 10000000 0", "TIMESTEP 1 1e300",
                 "TIMESTEP 100 1e6", "TIMESTEP 3 1e-13", "EPSINT 1e-300", "EPSIND 1e-300", "EPSKIN 1e-300",
                 "EPSINT 0.999", "HMAX 1e300", "HMAX 1e-300", "HMAX 1e-9", "MAXITERAT 1000", "MAXITERAT 1000000000",
                 "TIME 1e308", "TIME -1e308", "TIME 1e300", "TIME 5e-324", "XD 2 1 1e300", "XD 2 1 1e6",
                 "XDD 2 1 1e300", "MASS 8 1e308", "MASS 8 1e-300", "EMASS 1 1e308", "ESTIFF 2 1e308 1e308",
                 "ESTIFF 2 0 1e-300", "EDAMPP 2 1e300 1e300", "X 3 1e300 0", "X 8 1e-300 0", "X 3 0.15 1e-300",
                 "GRAVITY 0 -1e308", "GRAVITY 1e300 1e300", "FORCE 8 1e308", "E 2 2 1e300", "ED 2 2 1e300",
                 "LENGTHO 2 1e-300", "LENGTHO 2 1e300", "LGEOMY 2 1e300", "PLBEAM 2147483647 1 2 3 4",
                 "PLTRUSS 2147483647 1 8", "FIX 2147483647", "X 2147483647 1 0", "LINEAR 2", "LINE 2 1",
                 "FORCEMODE 2", "RESTART 1", "RLSE 2", "INPUTE 3 1", "ED 3 1 0.1", "DYNX 8 1", "INPUTX 8 1"]


# The edits of mutated_lines that need no pool beyond its token, keyword and new_line strategies
# ("extreme" needs extreme_line; "random_line" inserts a new_line, as "insert" does).
LINE_EDITS = ["delete", "duplicate", "swap", "token", "keyword", "insert", "append_token", "drop_token", "truncate"]


@st.composite
def mutated_lines(draw, lines, edits, max_edits, token, keyword, new_line, extreme_line=None):
    """The text of ``lines`` after 1 to ``max_edits`` random edits, each one of ``edits``: delete,
    duplicate or swap lines, replace a token (drawn from ``token``) or the keyword (``keyword``),
    insert a line (``new_line``; "random_line" does the same, "extreme" inserts an
    ``extreme_line`` anywhere), append or drop a token, or truncate the text anywhere."""
    lines = list(lines)
    for _ in range(draw(st.integers(1, max_edits))):
        op = draw(st.sampled_from(edits))
        if not lines:
            lines.append(draw(new_line))
            continue
        i = draw(st.integers(0, len(lines) - 1))
        words = lines[i].split()
        if op == "delete":
            del lines[i]
        elif op == "duplicate":
            lines.insert(i, lines[i])
        elif op == "swap":
            j = draw(st.integers(0, len(lines) - 1))
            lines[i], lines[j] = lines[j], lines[i]
        elif op == "token" and words:
            words[draw(st.integers(0, len(words) - 1))] = draw(token)
            lines[i] = " ".join(words)
        elif op == "keyword" and words:
            words[0] = draw(keyword)
            lines[i] = " ".join(words)
        elif op in ("insert", "random_line"):
            lines.insert(i, draw(new_line))
        elif op == "extreme":
            lines.insert(draw(st.integers(0, len(lines) - 1)), draw(extreme_line))
        elif op == "append_token":
            lines[i] = " ".join(words + [draw(token)])
        elif op == "drop_token" and words:
            lines[i] = " ".join(words[:-1])
        elif op == "truncate":
            text = "\n".join(lines)
            lines = text[:draw(st.integers(0, len(text)))].split("\n")
    return "\n".join(lines) + "\n"


def mutated_example():
    """The manual's slider-crank with 1 to 3 edits, random keyword lines and extreme values among them."""
    return mutated_lines(EXAMPLE_LINES, ["delete", "duplicate", "swap", "token", "keyword", "insert", "extreme",
                                         "append_token", "drop_token", "truncate", "random_line"],
                         max_edits=3, token=tokens(), keyword=st.sampled_from(_keyword_names()),
                         new_line=keyword_line(), extreme_line=st.sampled_from(EXTREME_LINES))


def _catalogue():
    return {t.name: t for t in spacar.element_catalogue()}


QUATERNIONS = [(1, 0, 0, 0), (0.6, 0.8, 0, 0), (0, 0, 0, 1), (0.5, 0.5, 0.5, 0.5), (0.6, 0, 0.8, 0)]


SIZES = {"XY": 2, "BETA": 1, "XYZ": 3, "LAMBDA": 4}


@st.composite
def random_model(draw, max_elements=12):
    """A model built from the catalogue: mostly consistent topology, classes and properties
    (indices within range, value counts per element type), values from benign and extreme pools,
    now and then a wild line."""
    cat = _catalogue()
    planar = draw(st.booleans())
    names = [n for n, t in cat.items() if (t.nodes[0].name in ("XY", "BETA")) == planar]
    names = names or ["PLTRUSS"]
    kinds: dict[int, str] = {}
    types: dict[int, object] = {}
    lines = []
    n_el = draw(st.integers(1, max_elements))
    base = draw(st.sampled_from([0, 0, 0, 100, 2**31 - 1 - 4 * max_elements - 10]))
    value = st.sampled_from(["0.1", "1", "0.01", "0.5", "2", "1e-3", "1e3", "0", "3", "1e-6"])
    wild = st.one_of(st.sampled_from(["-0.5", "1e300", "1e-300", "1e308", "-1"]), value)
    for e in range(1, n_el + 1):
        t = cat[draw(st.sampled_from(names))]
        nodes = []
        for k in t.nodes:
            same_kind = [n for n, kk in kinds.items() if kk == k.name and n not in nodes]
            if same_kind and draw(st.integers(0, 2)) > 0:
                nodes.append(draw(st.sampled_from(same_kind)))
            else:
                n = base + len(kinds) + 1
                while n in kinds:
                    n += 1
                kinds[n] = k.name
                nodes.append(n)
        params = [draw(st.sampled_from(["0", "1", "0.5", "-1", "0.1"])) for _ in range(t.n_params_min)]
        if t.name in ("BEAM", "BEAMNL", "BEARING", "HINGE") and draw(st.integers(0, 3)) > 0:
            params = draw(st.sampled_from([["0", "1", "0"], ["0", "0", "1"], ["1", "0", "0"]]))
        lines.append(" ".join([t.name, str(base + e)] + [str(n) for n in nodes] + params))
        types[base + e] = t
    for n, k in kinds.items():
        if k in ("XY", "XYZ") and draw(st.integers(0, 5)) > 0:
            coords = [f"{draw(st.integers(-3, 3))}.{draw(st.integers(0, 9))}" for _ in range(SIZES[k])]
            lines.append(f"X {n} " + " ".join(coords))
        elif k == "LAMBDA" and draw(st.booleans()):
            lines.append("LAMBDA {} {} {} {} {}".format(n, *draw(st.sampled_from(QUATERNIONS))))
        elif k == "BETA" and draw(st.integers(0, 3)) == 0:
            lines.append(f"BETA {n} {draw(st.sampled_from(['0.5', '-1', '3.14159', '100']))}")
    node_ids = sorted(kinds)
    elements = sorted(types)
    lines.append(f"FIX {node_ids[0]}")
    for _ in range(draw(st.integers(0, 10))):
        n = draw(st.sampled_from(node_ids))
        e = draw(st.sampled_from(elements))
        t = types[e]
        c = draw(st.integers(1, SIZES[kinds[n]]))
        i = draw(st.integers(1, max(1, t.n_deformations)))
        kw = draw(st.sampled_from(["FIX", "FIX", "INPUTX", "DYNX", "DYNX", "RLSE", "INPUTE", "DYNE", "DYNE", "LINE",
                                   "XD", "XD", "E", "ED", "MASS", "MASS", "EMASS", "ESTIFF", "ESTIFF", "EDAMPP",
                                   "FORCE", "TORQUEL", "ENHC", "DIR", "LENGTHO", "LGEOMY", "XDD", "EDD", "GRAVITY",
                                   "wild"]))
        v = draw(value)
        if kw == "MASS":
            line = f"MASS {n} " + (" ".join(draw(value) for _ in range(6)) if kinds[n] == "LAMBDA" else draw(wild))
        elif kw == "ESTIFF":
            line = f"ESTIFF {e} " + " ".join(draw(wild) for _ in range(max(1, t.n_estiff)))
        elif kw == "EMASS":
            line = f"EMASS {e} " + " ".join(draw(value) for _ in range(max(1, min(t.n_emass, 2))))
        elif kw == "LGEOMY":
            line = f"LGEOMY {e} " + " ".join(draw(value) for _ in range(max(1, t.n_lgeomy)))
        elif kw == "FORCE":
            line = f"FORCE {n} " + " ".join(draw(wild) for _ in range(SIZES[kinds[n]]))
        elif kw == "wild":
            line = draw(keyword_line())
        else:
            line = {"FIX": f"FIX {n} {c}", "INPUTX": f"INPUTX {n} {c}", "DYNX": f"DYNX {n}", "RLSE": f"RLSE {e} {i}",
                    "INPUTE": f"INPUTE {e} {i}", "DYNE": f"DYNE {e} {i}", "LINE": f"LINE {e} {i}",
                    "XD": f"XD {n} {c} {v}", "XDD": f"XDD {n} {c} {v}", "E": f"E {e} {i} {v}", "ED": f"ED {e} {i} {v}",
                    "EDD": f"EDD {e} {i} {v}", "EDAMPP": f"EDAMPP {e} {v}", "TORQUEL": f"TORQUEL {n} {v}",
                    "ENHC": f"ENHC {e} {i} {draw(st.sampled_from(elements))} 1", "DIR": f"DIR {e} 0 0 1",
                    "LENGTHO": f"LENGTHO {e} {v}", "GRAVITY": "GRAVITY 0 -9.81" + (" 0" if not planar else "")}[kw]
        lines.append(line)
    if draw(st.integers(0, 3)) == 0:
        lines.append(draw(st.sampled_from(EXTREME_LINES)))
    n_out = draw(st.sampled_from([0, 1, 2, 3, 10]))
    period = "0" if n_out == 0 else draw(st.sampled_from(["0", "0.01", "0.1", "1"]))
    lines.append(f"TIMESTEP {n_out} {period}")
    lines.append("END")
    if draw(st.integers(0, 4)) == 0:
        lines += [draw(keyword_line()), "END"]
    return "\n".join(lines) + "\n"


@st.composite
def chain_model(draw, max_size=60):
    """A chain of n elements (deep numbers of nodes), possibly numbered up to 2^31 - 1."""
    n = draw(st.integers(1, max_size))
    spatial = draw(st.booleans())
    offset = draw(st.sampled_from([0, 1000, 2**31 - 2 * max_size - 5]))
    kind = "TRUSS" if spatial else draw(st.sampled_from(["PLTRUSS", "PLBEAM"]))
    lines = []
    for i in range(1, n + 1):
        if kind == "PLBEAM":
            a, b = offset + 2 * i - 1, offset + 2 * i + 1
            lines.append(f"PLBEAM {offset + i} {a} {a + 1} {b} {b + 1}")
            lines.append(f"X {b} {i}.0 0.0")
        else:
            lines.append(f"{kind} {offset + i} {offset + i} {offset + i + 1}")
            lines.append(f"X {offset + i + 1} {i}.0 0.0" + (" 0.0" if spatial else ""))
    first = offset + 1
    lines.append(f"X {first} 0.0 0.0" + (" 0.0" if spatial else ""))
    lines.append(f"FIX {first}")
    if kind == "PLBEAM":
        lines.append(f"FIX {first + 1}")
    if draw(st.booleans()):
        last = offset + (2 * n + 1 if kind == "PLBEAM" else n + 1)
        lines.append(f"DYNX {last}")
        lines.append(f"MASS {last} 1.0")
    lines.append(f"TIMESTEP {draw(st.sampled_from([1, 2]))} 0.01")
    lines.append("END")
    return "\n".join(lines) + "\n"


@st.composite
def line_soup(draw):
    return "\n".join(draw(st.lists(keyword_line(), min_size=1, max_size=20))) + "\n"


@st.composite
def decorate(draw, text):
    """Lexical variations that must not matter (or must fail cleanly): CR/LF, tabs, comments,
    leading blanks, NULs, an EOF."""
    op = draw(st.integers(0, 9))
    if op == 0:
        return text.replace("\n", "\r\n")
    if op == 1:
        return text.replace(" ", "\t")
    if op == 2:
        return "* a comment\n" + text + "* trailing\n"
    if op == 3:
        return text + "EOF\n" + draw(st.sampled_from(["", "garbage\n", "END\n"]))
    if op == 4:
        return text.replace("\n", "\n ", draw(st.integers(0, 3)))
    if op == 5:
        return text[: draw(st.integers(0, len(text)))] + "\x00" + text[len(text) // 2:]
    if op == 6:
        return text.lower()
    return text


@dataclass
class Case:
    """One fuzzed input: an input text or a Python API program, with what to run on it."""

    kind: str                      # "text" or "api"
    source: str = ""               # the generator
    text: str = ""
    program: list = field(default_factory=list)
    simulate: bool = False
    linearize: bool = False

    def describe(self) -> str:
        if self.kind == "text":
            return f"text from {self.source} (simulate={self.simulate}, linearize={self.linearize}):\n{self.text}"
        return "api program:\n" + "\n".join(f"  {name}({', '.join(show(a) for a in args)})"
                                               for name, args in self.program)


BUILDERS = sorted({kw.builder for kw in KEYWORDS.values() if kw.name not in ("END", "EOF")})
API_EXTRAS = ["apply", "copy", "pickle", "summary", "check", "dump", "simulate", "linearize", "results", "sweep",
              "set_memory_limit", "read_string"]


@st.composite
def api_program(draw):
    steps = []
    for _ in range(draw(st.integers(1, 8))):
        name = draw(st.sampled_from(BUILDERS + API_EXTRAS))
        if name in BUILDERS and draw(st.booleans()):
            # Mostly plausible arguments, one replaced by something hostile.
            kw = next(k for k in KEYWORDS.values() if k.builder == name)
            args = []
            for p in kw.params:
                for _ in range(p.count_min if p.count_min else draw(st.integers(0, 2))):
                    args.append(draw(st.integers(1, 9)) if p.kind == INT else draw(st.floats(-2, 2)))
            if args:
                args[draw(st.integers(0, len(args) - 1))] = draw(st.sampled_from(PY_VALUES))
        else:
            args = draw(st.lists(st.one_of(st.sampled_from(PY_VALUES), st.integers(-2, 9),
                                           st.floats(allow_nan=True, allow_infinity=True)), max_size=6))
        steps.append((name, tuple(args)))
    return steps


def cases(max_size=60):
    """The strategy of all fuzzed cases: three quarters input texts (from five generators, with
    lexical decorations), one quarter API programs. A quarter of the texts that read are also
    simulated, an eighth linearized."""
    generators = {"mutated example": mutated_example(), "random model": random_model(),
                  "small random model": random_model(max_elements=4), "line soup": line_soup(),
                  "chain": chain_model(max_size=max_size)}
    text = st.sampled_from(sorted(generators)).flatmap(
        lambda name: generators[name].flatmap(decorate).map(lambda t: (name, t)))
    text_case = st.builds(lambda nt, s, lin: Case("text", source=nt[0], text=nt[1], simulate=s, linearize=lin),
                          text, st.integers(0, 3).map(lambda k: k == 0), st.integers(0, 7).map(lambda k: k == 0))
    api_case = st.builds(lambda p: Case("api", source="api", program=p), api_program())
    return st.integers(0, 3).flatmap(lambda k: api_case if k == 0 else text_case)


# --- the oracle ---------------------------------------------------------------------------------------

def _allowed(err: BaseException) -> bool:
    if isinstance(err, SpacarError):
        return True
    return isinstance(err, TypeError) and bool(ARITY.search(str(err)))


def _check_results(res, where):
    for name in ("t", "x", "xd", "xdd", "e", "ed", "edd", "sigma", "reaction"):
        arr = getattr(res, name)
        if not np.isfinite(arr).all():
            raise Finding(f"{where}: a successful run gave non-finite values in {name}")


def _roundtrips(model, where):
    dump = model.dump(digits=17)
    try:
        again = spacar.read_string(dump, "dump.dat")
    except SpacarError as err:
        raise Finding(f"{where}: the state dump does not read back: {type(err).__name__}: {err}\n{dump}") from None
    if again.dump(digits=17) != dump:
        raise Finding(f"{where}: the state dump read back gives another dump\n{dump}\n---\n{again.dump(digits=17)}")
    if pickle.loads(pickle.dumps(model)).dump(digits=17) != dump:
        raise Finding(f"{where}: pickling changes the model")


def _run_text(case: Case, max_outputs) -> str:
    try:
        model = spacar.read_string(case.text, "fuzz.dat")
    except SpacarError as err:
        if not str(err).startswith("fuzz.dat, line "):
            raise Finding(f"a reader error does not name file and line: {err}") from None
        return "read:" + type(err).__name__
    summary = model.summary()
    str(summary)
    if summary.n_coordinates <= 600:
        str(model.check())
    _roundtrips(model, "before the analysis")
    if not (case.simulate or case.linearize):
        return "read"
    outcome = "read"
    if case.simulate:
        s = model.settings
        if max_outputs is not None and s.timestep_n > max_outputs:
            model.timestep(max_outputs, s.timestep_tp)
        res = spacar.simulate(model, time_limit=SIM_TIME_LIMIT)
        _check_results(res, "simulate")
        _roundtrips(model, "after the analysis")
        for block in model.blocks[1:2]:
            spacar.io.reader.apply_block(model, block)
            if max_outputs is not None and model.settings.timestep_n > max_outputs:
                model.timestep(max_outputs, model.settings.timestep_tp)
            _check_results(spacar.simulate(model, time_limit=SIM_TIME_LIMIT), "simulate (block 2)")
        outcome = "simulated"
    if case.linearize:
        lin = spacar.linearize(model)
        for name in ("M0", "K0", "C0", "D0", "N0", "G0"):
            getattr(lin, name)
        lin.eigenfrequencies()
        outcome += "+linearized"
    return outcome


def _run_api(case: Case) -> str:
    model = spacar.read_string(EXAMPLE) if case.program and case.program[0][0] != "apply" else spacar.Model()
    res = None
    for name, args in case.program:
        try:
            if name in BUILDERS:
                getattr(model, name)(*args)
            elif name == "apply":
                model.apply(*args) if args and isinstance(args[0], str) else model.apply("FIX", *args)
            elif name == "copy":
                model = model.copy()
            elif name == "pickle":
                model = pickle.loads(pickle.dumps(model))
            elif name == "summary":
                str(model.summary())
            elif name == "check":
                if model.summary().n_coordinates <= 600:
                    str(model.check())
            elif name == "dump":
                model.dump(*args[:1])
            elif name == "simulate":
                kwargs = dict(zip(("time_limit", "method", "on_output"), args))
                if "time_limit" not in kwargs or kwargs["time_limit"] is None:
                    kwargs["time_limit"] = SIM_TIME_LIMIT
                if model.settings.timestep_n > 4:
                    model.timestep(4, model.settings.timestep_tp)
                res = spacar.simulate(model.copy(), **kwargs)
            elif name == "linearize":
                spacar.linearize(model.copy(), *args[:1])
            elif name == "results" and res is not None:
                for method in (res.node, res.element, res.coordinate, res.deformation, res.coordinate_index):
                    try:
                        method(*args[:2])
                    except SpacarError:
                        pass
            elif name == "sweep":
                params = {args[0] if args and isinstance(args[0], (str, tuple)) else "XD 2 1": list(args[1:2]) or [1.0]}
                params.setdefault("TIMESTEP", [(1, 0.01)])
                spacar.sweep(spacar.read_string(EXAMPLE), params, workers=1, progress=False)
            elif name == "set_memory_limit":
                spacar.set_memory_limit(*args[:1])
            elif name == "read_string":
                spacar.read_string(*args[:2])
        except Exception as err:  # noqa: BLE001
            if not _allowed(err):
                raise
        finally:
            if name == "set_memory_limit":
                spacar.set_memory_limit(FUZZ_MEMORY_LIMIT)
    return "api"


def run_case(case: Case, max_outputs=4) -> str:
    """Run one case; returns an outcome label, raises Finding for a broken rule (including any
    exception that is not a SpacarError)."""
    spacar.set_memory_limit(FUZZ_MEMORY_LIMIT)
    start = time.perf_counter()
    try:
        outcome = _run_text(case, max_outputs) if case.kind == "text" else _run_api(case)
    except Finding:
        raise
    except Exception as err:  # noqa: BLE001
        if _allowed(err):
            outcome = "error:" + type(err).__name__
        else:
            raise Finding(f"{type(err).__module__}.{type(err).__name__}: {err}\n"
                          f"{''.join(traceback.format_exception(err)[-4:])}") from err
    elapsed = time.perf_counter() - start
    if elapsed > SLOW_CASE:
        raise Finding(f"the case took {elapsed:.1f} s")
    return outcome


# --- files: spacar.read of a file and Results.load (issue 24) -------------------------------------------
#
# The reader's file path (regular files only, size and line caps, line by line) must agree with
# read_string on every text; Results.load must refuse every malformed file with an InputError naming
# it, and a file whose arrays would exceed the memory limit before decompressing it. Cases that
# ended differently from each other are kept as a corpus in tests/data/fuzz/ and replayed by
# tests/io/test_hostile_fuzz.py.

CORPUS = ROOT / "tests" / "data" / "fuzz"
FILE_SLOW_CASE = 5.0  # seconds: reading or loading one file slower than this is a finding
CORPUS_MAX_BYTES = 100_000  # larger cases are run but not kept
RESULTS_MEMORY_LIMIT = 16 * 2**20  # while loading fuzzed results files: bombs stay cheap to make


def _outcome_of(call, path) -> str:
    """"ok" or "<error type>: <message with the path and numbers removed>"."""
    try:
        call()
        return "ok"
    except SpacarError as err:
        message = str(err).replace(str(path), "<file>")
        # the kind of error: its first words, without numbers, names and quoted values
        message = re.sub(r"'[^']*'|\"[^\"]*\"|\([^)]*\)|[0-9]+", "_", message)
        return f"{type(err).__name__}: {message[:48]}"


def run_reader_file(text: str, directory: Path) -> str:
    """Write ``text`` to a file and read it with spacar.read: the outcome must equal read_string's
    (the same dump, or the same error); only SpacarErrors; bounded time."""
    path = Path(directory) / "fuzz.dat"
    path.write_bytes(text.encode("utf-8", "surrogatepass"))
    start = time.perf_counter()
    try:
        from_file = spacar.read(path).dump(digits=17)
    except SpacarError as err:
        from_file = f"{type(err).__name__}: {err}"
    except Exception as err:  # noqa: BLE001
        raise Finding(f"spacar.read raised {type(err).__name__}: {err}") from err
    if time.perf_counter() - start > FILE_SLOW_CASE:
        raise Finding(f"reading the file took {time.perf_counter() - start:.1f} s")
    try:
        from_text = spacar.read_string(path.read_text("utf-8", "replace"), str(path)).dump(digits=17)
    except SpacarError as err:
        from_text = f"{type(err).__name__}: {err}"
    if from_file != from_text:
        raise Finding(f"spacar.read and read_string differ:\n{from_file[:500]}\n---\n{from_text[:500]}")
    if len(from_file) > 2000 and from_file.startswith(("InputError", "SpacarError")):
        raise Finding(f"a reader message of {len(from_file)} characters")
    return "read" if not from_file.startswith(("InputError", "SpacarError")) else "read:InputError"


_GOOD_RESULTS = {}


def good_results_file() -> bytes:
    """A saved spacar.Results with linearizations (3 output times of the slider-crank)."""
    if "data" not in _GOOD_RESULTS:
        model = spacar.read_string(EXAMPLE)
        model.apply("LINEAR", 1)
        model.apply("FORCEMODE", 1)
        model.timestep(2, 0.1)
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "good.npz"
            spacar.simulate(model, progress=False).save(path)
            _GOOD_RESULTS["data"] = path.read_bytes()
    return _GOOD_RESULTS["data"]


def _npz(arrays: dict, compressed=True) -> bytes:
    import io

    buf = io.BytesIO()
    (np.savez_compressed if compressed else np.savez)(buf, **arrays)
    return buf.getvalue()


def _arrays_of(data: bytes) -> dict:
    import io

    with np.load(io.BytesIO(data), allow_pickle=False) as f:
        return {name: f[name] for name in f.files}


RESULTS_EDITS = ["flip bytes", "truncate", "insert bytes", "drop array", "retype array", "reshape array",
                 "replace array", "meta value", "meta text", "bomb", "lying header", "extra member"]
_ODD_VALUES = [None, True, -1, 0, 2**31, 10**30, 1.5, float("nan"), "x", [], {}, [1, "a"], {"a": 1}, "\u2028"]
_ODD_DTYPES = ["<U3", "|S2", "<c16", "<i8", "<f4", "|b1", "<u2", "<m8[s]", "<M8[D]", "<f8"]


@st.composite
def results_file(draw):
    """A saved results file with one to three hostile edits, at the level of bytes, zip members,
    arrays or the JSON description."""
    data = good_results_file()
    for _ in range(draw(st.integers(1, 3))):
        edit = draw(st.sampled_from(RESULTS_EDITS))
        if edit in ("flip bytes", "truncate", "insert bytes"):
            n = len(data)
            if n == 0:
                continue
            at = draw(st.integers(0, n - 1))
            if edit == "flip bytes":
                data = data[:at] + bytes([data[at] ^ draw(st.integers(1, 255))]) + data[at + 1:]
            elif edit == "truncate":
                data = data[:at]
            else:
                data = data[:at] + draw(st.binary(min_size=1, max_size=64)) + data[at:]
            continue
        try:
            arrays = _arrays_of(data)
        except Exception:  # noqa: BLE001 - already broken by an earlier byte edit
            continue
        names = sorted(arrays)
        name = draw(st.sampled_from(names))
        if edit == "drop array":
            arrays.pop(name)
        elif edit == "retype array":
            try:
                with np.errstate(all="ignore"), warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    arrays[name] = arrays[name].astype(draw(st.sampled_from(_ODD_DTYPES)))
            except (TypeError, ValueError, OverflowError):
                arrays[name] = np.array(["x"] * max(arrays[name].size, 1))
        elif edit == "reshape array":
            shape = tuple(draw(st.lists(st.integers(0, 5), max_size=3)))
            arrays[name] = np.zeros(shape)
        elif edit == "replace array":
            arrays[name] = np.array(draw(st.sampled_from([np.nan, np.inf, -1, 2**62, "abc", 0.5])))
        elif edit in ("meta value", "meta text"):
            try:
                meta = json.loads(str(arrays["meta"])) if "meta" in arrays else {}
            except (ValueError, RecursionError):  # already broken by an earlier edit
                meta = {}
            if edit == "meta value" and isinstance(meta, dict):
                key = draw(st.sampled_from(sorted(meta) + ["format", "linearizations", "geometry", "stats"]))
                meta[key] = draw(st.sampled_from(_ODD_VALUES))
                arrays["meta"] = np.array(json.dumps(meta))
            else:
                arrays["meta"] = np.array(draw(st.sampled_from(["", "{", "[]", "null", "1e999", "[" * 5000,
                                                                '{"format": "spacar.Results"}'])))
        elif edit == "bomb":
            rows = draw(st.sampled_from([10**5, 10**6, 2 * 10**6]))  # 3 to 64 MB against RESULTS_MEMORY_LIMIT
            arrays[draw(st.sampled_from(["t", "x", "e", "lin0_M0"]))] = np.zeros((rows, 4))
            data = _npz(arrays, compressed=True)  # small on disk, large when inflated
            continue
        elif edit == "lying header":
            # a header that declares far more data than the member holds
            from numpy.lib import format as npy

            import io
            import zipfile

            buf = io.BytesIO()
            header = {"descr": "<f8", "fortran_order": False, "shape": (draw(st.integers(10**6, 10**12)),)}
            npy.write_array_header_1_0(buf, header)
            zbuf = io.BytesIO(_npz(arrays))
            with zipfile.ZipFile(zbuf, "a") as zf:
                zf.writestr("big.npy", buf.getvalue() + b"\0" * 64)
            data = zbuf.getvalue()
            continue
        elif edit == "extra member":
            arrays[draw(st.sampled_from(["lin7_M0", "lin0_XX", "other", "lin0_M0"]))] = np.zeros((2, 2))
        data = _npz(arrays, compressed=draw(st.booleans()))
    return data


def run_results_file(data: bytes, directory: Path) -> str:
    """Results.load of ``data``: a Results whose arrays have consistent shapes, or an InputError
    naming the file, within FILE_SLOW_CASE seconds, under RESULTS_MEMORY_LIMIT."""
    spacar.set_memory_limit(RESULTS_MEMORY_LIMIT)
    path = Path(directory) / "fuzz.npz"
    path.write_bytes(data)
    start = time.perf_counter()
    try:
        res = spacar.Results.load(path)
    except spacar.InputError as err:
        if not str(err).startswith(str(path)):
            raise Finding(f"a Results.load error does not name the file: {err}") from None
        if len(str(err)) > 1000:
            raise Finding(f"a Results.load message of {len(str(err))} characters")
        outcome = "refused"
    except Exception as err:  # noqa: BLE001
        raise Finding(f"Results.load raised {type(err).__module__}.{type(err).__name__}: {show(str(err))}\n"
                      f"{''.join(traceback.format_exception(err)[-4:])}") from err
    else:
        nt, nx, ne = len(res.t), len(res.coordinate_labels), len(res.deformation_labels)
        for name, cols in (("x", nx), ("xd", nx), ("xdd", nx), ("reaction", nx), ("e", ne), ("ed", ne),
                           ("edd", ne), ("sigma", ne)):
            if getattr(res, name).shape != (nt, cols):
                raise Finding(f"Results.load accepted {name} of shape {getattr(res, name).shape}")
        for lin in res.linearizations:
            lin.eigenfrequencies()
        outcome = "loaded"
    if time.perf_counter() - start > FILE_SLOW_CASE:
        raise Finding(f"loading took {time.perf_counter() - start:.1f} s")
    return outcome


def corpus_files(kind: str) -> list:
    """The corpus of ``kind`` ("reader" or "results") kept in tests/data/fuzz/<kind>/."""
    return sorted((CORPUS / kind).glob("*"))


def grow_corpus(kind: str, cases: int, seed_: int = 0) -> dict:
    """Run ``cases`` hypothesis cases of ``kind`` and keep in the corpus the first case of every
    distinct outcome (error messages without numbers) not yet in it. Returns the tallies."""
    (CORPUS / kind).mkdir(parents=True, exist_ok=True)
    seen = set()
    with tempfile.TemporaryDirectory() as tmp:
        for f in corpus_files(kind):
            seen.add(_corpus_outcome(kind, f.read_bytes(), Path(tmp)))
        tally = Counter()
        strategy = results_file() if kind == "results" else cases_text()

        @seed(seed_)
        @settings(max_examples=cases, database=None, deadline=None, phases=[Phase.generate],
                  suppress_health_check=list(HealthCheck))
        @given(strategy)
        def one(data):
            if kind == "reader":
                data = data.encode("utf-8", "surrogatepass")
            outcome = _corpus_outcome(kind, data, Path(tmp))
            tally[outcome.split(":")[0]] += 1
            if outcome not in seen and len(data) <= CORPUS_MAX_BYTES:
                seen.add(outcome)
                name = f"{len(list((CORPUS / kind).glob('*'))):04d}.{'npz' if kind == 'results' else 'dat'}"
                (CORPUS / kind / name).write_bytes(data)

        one()
    return dict(tally)


def _corpus_outcome(kind: str, data: bytes, directory: Path) -> str:
    if kind == "results":
        run_results_file(data, directory)
        path = directory / "fuzz.npz"
        return _outcome_of(lambda: spacar.Results.load(path), path)
    run_reader_file(data.decode("utf-8", "replace"), directory)
    path = directory / "fuzz.dat"
    return _outcome_of(lambda: spacar.read(path), path)


def cases_text():
    """Input texts only (the text generators of cases(), decorated)."""
    generators = {"mutated example": mutated_example(), "random model": random_model(),
                  "small random model": random_model(max_elements=4), "line soup": line_soup(),
                  "chain": chain_model(max_size=60)}
    return st.sampled_from(sorted(generators)).flatmap(lambda name: generators[name].flatmap(decorate))


# --- the long campaign ------------------------------------------------------------------------------

def _worker(args):
    """Run ``args.cases`` cases with seed ``args.seed``; record outcomes and findings; write the
    current case before running it (a crash leaves it on disk) and the tallies now and then."""
    state = Path(args.state)
    current = state.with_suffix(".current")
    fault = open(state.with_suffix(".fault"), "w")
    faulthandler.enable(fault)
    tally, findings, slowest = Counter(), [], []
    count = 0
    started = time.perf_counter()

    def save(final=False):
        data = {"seed": args.seed, "cases": count, "seconds": time.perf_counter() - started, "outcomes": tally,
                "findings": findings, "slowest": sorted(slowest, reverse=True)[:10], "final": final}
        tmp = state.with_suffix(".tmp")
        tmp.write_text(json.dumps(data, default=str))
        os.replace(tmp, state)

    @seed(args.seed)
    @settings(max_examples=args.cases, database=None, deadline=None, phases=[Phase.generate],
              suppress_health_check=list(HealthCheck))
    @given(cases(max_size=args.max_size))
    def one_case(case):
        nonlocal count
        current.write_text(case.describe())
        t0 = time.perf_counter()
        try:
            tally[f"{case.source}: {run_case(case, max_outputs=args.max_outputs)}"] += 1
        except Finding as finding:
            tally[f"{case.source}: FINDING"] += 1
            findings.append({"finding": str(finding)[:4000], "case": case.describe()[:20000]})
        dt = time.perf_counter() - t0
        if len(slowest) < 10 or dt > min(slowest)[0]:
            slowest.append((dt, case.describe()[:300]))
            slowest.sort(reverse=True)
            del slowest[10:]
        count += 1
        if count % 500 == 0:
            save()

    one_case()
    save(final=True)


def campaign(total: int, workers: int, report: Path, max_size=300, max_outputs=None, hang=120.0, seed0=None):
    """Run ``total`` cases in ``workers`` processes; returns the report (also written as JSON).
    A worker that dies (crash) or stops starting cases for ``hang`` seconds is recorded with
    its last case, and a new worker continues with a new seed."""
    seed0 = int(time.time()) if seed0 is None else seed0
    tmp = Path(tempfile.mkdtemp(prefix="spacar-fuzz-"))
    per = math.ceil(total / workers)
    queue = [(seed0 + i, min(per, total - i * per)) for i in range(workers) if total - i * per > 0]
    running, results, incidents = {}, [], []
    next_seed = seed0 + workers
    start = time.perf_counter()

    def launch(s, n):
        state = tmp / f"worker-{s}.json"
        cmd = [sys.executable, __file__, "--worker", "--seed", str(s), "--cases", str(n), "--state", str(state),
               "--max-size", str(max_size)] + (["--max-outputs", str(max_outputs)] if max_outputs else [])
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        running[proc.pid] = (proc, s, n, state)

    for s, n in queue:
        launch(s, n)
    while running:
        time.sleep(1.0)
        for pid, (proc, s, n, state) in list(running.items()):
            current = state.with_suffix(".current")
            rc = proc.poll()
            if rc is None:
                last = current.stat().st_mtime if current.exists() else state.parent.stat().st_mtime
                if time.time() - last > hang:
                    proc.kill()
                    proc.wait()
                    rc = "hang"
                else:
                    continue
            del running[pid]
            done = json.loads(state.read_text()) if state.exists() else {"cases": 0, "outcomes": {}, "findings": [],
                                                                          "slowest": [], "seconds": 0}
            results.append(done)
            if rc != 0:
                stderr = proc.stderr.read().decode(errors="replace")[-4000:] if proc.stderr else ""
                fault = state.with_suffix(".fault")
                incidents.append({"kind": "hang" if rc == "hang" else f"crash (exit {rc})", "seed": s,
                                  "case": current.read_text()[:20000] if current.exists() else "?",
                                  "stderr": stderr, "fault": fault.read_text()[-4000:] if fault.exists() else ""})
                remaining = n - done.get("cases", 0) - 1
                if remaining > 0:
                    launch(next_seed, remaining)
                    next_seed += 1
    outcomes = Counter()
    for r in results:
        outcomes.update(r.get("outcomes", {}))
    slowest = sorted((tuple(x) for r in results for x in r.get("slowest", [])), reverse=True)[:10]
    data = {"cases": sum(r.get("cases", 0) for r in results) + len(incidents), "workers": workers,
            "seconds": round(time.perf_counter() - start, 1), "seed": seed0, "max_size": max_size,
            "max_outputs": max_outputs, "outcomes": dict(sorted(outcomes.items())),
            "findings": [f for r in results for f in r.get("findings", [])], "incidents": incidents,
            "slowest": slowest}
    report.write_text(json.dumps(data, indent=1, default=str))
    return data


def main(argv=None):
    parser = argparse.ArgumentParser(description="spacar fuzz campaign (see docs/robustness.md)")
    parser.add_argument("--cases", type=int, default=100_000)
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--report", type=Path, default=Path("fuzz-report.json"))
    parser.add_argument("--max-size", type=int, default=300, help="largest chain model (elements)")
    parser.add_argument("--max-outputs", type=int, default=None,
                        help="cap TIMESTEP n of simulated cases (default: none; the time limit bounds them)")
    parser.add_argument("--seed", type=int, default=None)
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--state", default=None, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        _worker(args)
        return 0
    data = campaign(args.cases, args.workers, args.report, args.max_size, args.max_outputs, seed0=args.seed)
    print(json.dumps({k: v for k, v in data.items() if k not in ("findings", "incidents", "slowest")}, indent=1))
    print(f"findings: {len(data['findings'])}, crashes/hangs: {len(data['incidents'])}; report: {args.report}")
    return 1 if data["findings"] or data["incidents"] else 0


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    sys.exit(main())
