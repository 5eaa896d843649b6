"""Guards against hostile input (issue #9): NaN and infinity are refused in every input value,
resource exhaustion is refused before anything is allocated, tolerances and step sizes that
would make the analysis crawl are refused or clamped, and a run that fails midway keeps the
results it computed up to the failure (``err.results``).
"""
from __future__ import annotations

import re
import time
from fractions import Fraction

import numpy as np
import pytest

import spacar
from spacar import InputError, KinematicsError, SpacarError, TimeLimitError
from spacar.keywords import INT, KEYWORDS, REAL
from support.paths import EXAMPLES

EXAMPLE = EXAMPLES / "slidercrank.dat"
TEXT = EXAMPLE.read_text()
BODY = TEXT.replace("END\n", "")


def with_lines(*lines: str) -> str:
    """The slider-crank with extra lines before its END."""
    return BODY + "".join(line + "\n" for line in lines) + "END\n"


# --- NaN and infinity in any input value ----------------------------------------------------

def _arguments(kw):
    """Valid-looking arguments of a keyword: (values, positions of the real values)."""
    args, reals = [], []
    for p in kw.params:
        count = max(p.count_min, 1 if p.kind == REAL else p.count_min)
        for _ in range(count):
            if p.kind == REAL:
                reals.append(len(args))
                args.append(0.5)
            else:
                args.append(1)
    return args, reals


REAL_SLOTS = [(name, i) for name, kw in sorted(KEYWORDS.items()) for i in _arguments(kw)[1]]
INT_SLOTS = [(name, i) for name, kw in sorted(KEYWORDS.items())
             for i, v in enumerate(_arguments(kw)[0]) if i not in _arguments(kw)[1]]
NON_FINITE = [float("nan"), float("inf"), float("-inf"), np.nan, np.float32("inf"), np.float64("-inf"), 10**400,
              Fraction(10**400, 3)]


def test_every_keyword_with_a_real_value_is_covered():
    assert len({name for name, _ in REAL_SLOTS}) >= 30
    assert len(REAL_SLOTS) >= 60


@pytest.mark.parametrize("name, slot", REAL_SLOTS, ids=[f"{n}-{i}" for n, i in REAL_SLOTS])
def test_builder_refuses_non_finite_reals(name, slot):
    kw = KEYWORDS[name]
    args, _ = _arguments(kw)
    for bad in NON_FINITE:
        values = list(args)
        values[slot] = bad
        with pytest.raises(InputError, match=rf"^{name}: \S+ must be a finite number"):
            getattr(spacar.Model(), kw.builder)(*values)


@pytest.mark.parametrize("name, slot", REAL_SLOTS, ids=[f"{n}-{i}" for n, i in REAL_SLOTS])
def test_reader_refuses_non_finite_reals(name, slot):
    args, _ = _arguments(KEYWORDS[name])
    for bad in ("nan", "NaN", "inf", "-Infinity", "+inf", "1e400", "-1.0D999"):
        tokens = [str(a) for a in args]
        tokens[slot] = bad
        text = f"* comment\n{name} {' '.join(tokens)}\nEND\n"
        with pytest.raises(InputError) as info:
            spacar.read_string(text, "nan.dat")
        message = str(info.value)
        assert message.startswith(f"nan.dat, line 2, keyword {name}: "), message
        assert re.search(r"not a number \(NaN and infinity are not accepted\)|must be a finite number", message), message


@pytest.mark.parametrize("name, slot", INT_SLOTS, ids=[f"{n}-{i}" for n, i in INT_SLOTS])
def test_integers_refuse_non_finite_and_huge_values(name, slot):
    kw = KEYWORDS[name]
    args, _ = _arguments(kw)
    for bad in (float("nan"), float("inf"), 2**31, -(2**31), 10**5000, 2.5, "1", None, [1], 1 + 0j, True):
        values = list(args)
        values[slot] = bad
        with pytest.raises(InputError, match=rf"^{name}: \S+ (must be an integer|must be a number|= .* is out of range)"):
            getattr(spacar.Model(), kw.builder)(*values)


def test_huge_digit_strings_are_refused_in_the_reader():
    with pytest.raises(InputError, match=r"line 1, keyword FIX: 9{20}\.\.\. \(5000 digits\) is out of range"):
        spacar.read_string("FIX " + "9" * 5000 + "\n")
    with pytest.raises(InputError, match=r"keyword MASS: m must be a finite number"):
        spacar.read_string("MASS 1 " + "9" * 5000 + "\n")


def test_python_api_refuses_non_finite_arguments():
    model = spacar.read(EXAMPLE)
    for bad in (float("nan"), float("inf"), -1.0, 0, "1", True):
        with pytest.raises(InputError, match="time_limit"):
            spacar.simulate(model.copy(), time_limit=bad)
    for bad in (float("nan"), 0, -5, 2**64, 1.5, "1"):
        with pytest.raises(InputError, match="memory limit"):
            spacar.set_memory_limit(bad)
    lin_model = spacar.read(EXAMPLE)
    nd = 4
    for state in [(float("nan"), np.zeros(nd), np.zeros(nd)), (0.0, np.full(nd, np.inf), np.zeros(nd)),
                  (0.0, np.zeros(nd), [0, 0, float("nan"), 0]), (0.0, "abc", np.zeros(nd)), (0.0,)]:
        with pytest.raises(InputError, match="state"):
            spacar.linearize(lin_model, state)


# --- resource exhaustion ----------------------------------------------------------------------

def test_result_arrays_beyond_the_memory_limit_are_refused():
    model = spacar.read_string(with_lines("TIMESTEP 10000000 5.0"))
    start = time.perf_counter()
    with pytest.raises(InputError, match=r"the results of 10000001 output times \(13 coordinates, 9 deformations\) "
                                         r"would need 7\.12 GB, more than the memory limit of 4\.29 GB"):
        spacar.simulate(model)
    assert time.perf_counter() - start < 1.0


def test_counts_beyond_the_input_limits_are_refused():
    with pytest.raises(InputError, match=r"TIMESTEP: too many output intervals \(1000000000\); at most 10\^7"):
        spacar.read_string(with_lines("TIMESTEP 1000000000 1"))
    with pytest.raises(InputError, match=r"MAXITERAT must be between 1 and 1000"):
        spacar.read_string(with_lines("MAXITERAT 1000000000"))


def chain(n: int) -> str:
    """A planar chain of n rigid PLTRUSS elements hanging from node 1 (n XY nodes free)."""
    lines = [f"PLTRUSS {i} {i} {i + 1}" for i in range(1, n + 1)]
    lines += [f"X {i} {i - 1}.0 0.0" for i in range(1, n + 2)]
    lines += ["FIX 1", "END"]
    return "\n".join(lines) + "\n"


def test_a_model_too_large_for_the_memory_limit_is_refused():
    old = spacar.memory_limit()
    try:
        spacar.set_memory_limit(1_000_000)
        model = spacar.read_string(chain(500))
        assert model.summary().n_coordinates == 1002
        with pytest.raises(InputError, match=r"the analysis of 1002 nodal coordinates and 500 deformations "
                                             r"would need .* more than the memory limit of 1 MB"):
            spacar.simulate(model)
        with pytest.raises(InputError, match=r"memory limit"):
            model.check()
    finally:
        spacar.set_memory_limit(old)
    assert spacar.memory_limit() == old


def cantilever(n: int) -> str:
    """A flexible cantilever of n PLBEAM elements, all deformations dynamic."""
    lines = [f"PLBEAM {i} {2 * i - 1} {2 * i} {2 * i + 1} {2 * i + 2}" for i in range(1, n + 1)]
    lines += [f"X {2 * i - 1} {(i - 1) / n} 0" for i in range(1, n + 2)]
    lines += ["FIX 1", "FIX 2"] + [f"DYNE {i} 1 2 3" for i in range(1, n + 1)]
    lines += [f"ESTIFF {i} 1e3 1" for i in range(1, n + 1)] + [f"EMASS {i} 0.1" for i in range(1, n + 1)]
    return "\n".join(lines + ["TIMESTEP 1 1e-4", "END"]) + "\n"


def test_the_dense_linearization_has_its_own_memory_check():
    # The simulation runs on sparse matrices (a few MB for 300 beams), and so do the linearization
    # at rest and its lowest modes (docs/formulation.md §10); the dense reduced matrices need the dense
    # transfer functions and mass matrices (65 MB) and are refused before allocating.
    old = spacar.memory_limit()
    try:
        spacar.set_memory_limit(10_000_000)
        model = spacar.read_string(cantilever(300))
        res = spacar.simulate(model)
        assert np.isfinite(res.x).all()
        lin = spacar.linearize(model)
        assert np.isfinite(lin.eigenfrequencies(k=3)).all()
        with pytest.raises(InputError, match=r"the dense transfer functions and mass matrices of 903 nodal "
                                             r"coordinates and 900 deformations would need .* more than the "
                                             r"memory limit of 10 MB"):
            lin.M0
    finally:
        spacar.set_memory_limit(old)


def test_enormous_element_and_node_numbers():
    big = 2**31 - 1
    text = f"BEAM {big} {big} 2 {big - 1} 4 0 1 0\nX {big - 1} 1.0 0 0\nFIX {big}\nFIX 2\nEND\n"
    model = spacar.read_string(text)
    summary = model.summary()
    assert summary.elements["L2MIN1"] == 2  # the automatic normalisation constraints found numbers
    again = spacar.read_string(model.dump(digits=17))
    assert again.dump(digits=17) == model.dump(digits=17)
    assert sorted(e for e, el in again.elements.items() if el.type_name == "L2MIN1") == [1, 2]


# --- tolerances and step sizes that would make the analysis crawl or hang ----------------------

def test_tiny_integration_tolerances_are_clamped_with_a_warning():
    model = spacar.read_string(with_lines("EPSINT 1e-300", "EPSIND 1e-300", "TIMESTEP 10 0.5"))
    start = time.perf_counter()
    res = spacar.simulate(model)
    assert time.perf_counter() - start < 5.0
    assert res.t[-1] == 0.5
    assert any(re.match(r"EPSINT 1e-300 is below the attainable accuracy in double precision: 2\.22\d*e-14", w)
               for w in model.warnings), model.warnings
    assert any(w.startswith("EPSIND 1e-300") for w in model.warnings)
    assert "EPSINT   1.000E-300" in model.dump()  # the model keeps what was given


def test_tiny_kinematic_tolerance_fails_within_maxiterat():
    model = spacar.read_string(with_lines("EPSKIN 1e-300", "MAXITERAT 1000"))
    start = time.perf_counter()
    with pytest.raises(KinematicsError, match=r"did not converge in 1000 iterations"):
        spacar.simulate(model)
    assert time.perf_counter() - start < 5.0


@pytest.mark.parametrize("lines, reason", [
    (["HMAX 1e-300"], r"HMAX 1e-300 is below the smallest integration step 1e-12"),
    (["HMAX 1e-9"], r"HMAX 1e-09 needs at least Tp/HMAX = 5000000000 steps, more than the limit of 10000000"),
    (["TIME 1e300"], r"the output interval Tp/n = 0\.05 is lost in the rounding of the time t = 1e\+300"),
    (["TIME 1e308", "TIMESTEP 10 1e308"], r"the end time TIME \+ Tp = 1e\+308 \+ 1e\+308 is not a finite number"),
    (["TIMESTEP 1 1e-13"], r"the period Tp = 1e-13 is shorter than the smallest integration step 1e-12"),
], ids=["hmax-tiny", "hmax-too-many-steps", "time-resolution", "end-time-overflow", "period-too-short"])
def test_impossible_time_settings_are_refused_before_any_work(lines, reason):
    model = spacar.read_string(with_lines(*lines))
    with pytest.raises(InputError, match=reason):
        spacar.simulate(model)


def test_huge_hmax_is_harmless():
    model = spacar.read_string(with_lines("HMAX 1e300"))
    reference = spacar.simulate(spacar.read(EXAMPLE))
    res = spacar.simulate(model)
    np.testing.assert_array_equal(res.x, reference.x)


def test_overflowing_stiffness_stops_with_a_clear_error():
    model = spacar.read_string(TEXT.replace("ESTIFF 2 0. 0.0012723", "ESTIFF 2 0. 1e308"))
    with pytest.raises(SpacarError, match=r"the accelerations at t = 0 are not finite: the model's values exceed "
                                          r"double precision"):
        spacar.simulate(model)


# --- a run that fails midway keeps its results ---------------------------------------------------

LONG_CRANK = {"X 3 0.15 0.": "X 3 0.4 0.", "X 6 0.30 0.": "X 6 0.5 0.", "X 8 0.45 0.": "X 8 0.6 0."}


def long_crank(dynamic: bool) -> str:
    """The slider-crank with a crank longer than the rod: at a crank angle of about 0.5 rad the
    rod cannot reach the slider's line any more, and the kinematics has no solution."""
    text = TEXT
    for a, b in LONG_CRANK.items():
        text = text.replace(a, b)
    if not dynamic:
        text = "".join(line for line in text.splitlines(keepends=True) if not line.startswith("DYNE"))
    return text


@pytest.mark.parametrize("dynamic", [False, True], ids=["kinematic", "dynamic"])
def test_a_failure_midway_keeps_the_results_computed_so_far(dynamic):
    model = spacar.read_string(long_crank(dynamic))
    dump_before = model.dump(digits=17)
    with pytest.raises(KinematicsError, match=r"Newton iteration on the positions did not converge|"
                                              r"No kinematic solution down to the minimum step") as info:
        spacar.simulate(model)
    res = info.value.results
    assert isinstance(res, spacar.Results)
    assert len(res) == 7 and res.t[-1] == pytest.approx(0.3)
    assert res.x.shape == (7, 13) and res.e.shape == (7, 9) and res.sigma.shape == (7, 9)
    assert np.isfinite(res.x).all()
    # The crank angle follows the input up to the failure.
    np.testing.assert_allclose(res.node(2).x[:, 0], 1.5 * res.t, rtol=1e-12)
    assert "7 output times from t = 0 to 0.3" in repr(res)
    if dynamic:
        assert res.stats["steps"] > 0 and res.stats["rhs_evaluations"] > 0
    # The model keeps its state from before the block.
    assert model.dump(digits=17) == dump_before


def test_a_time_limit_stops_the_run_and_keeps_exactly_the_rows_computed():
    full = spacar.simulate(spacar.read(EXAMPLE))
    model = spacar.read(EXAMPLE)
    with pytest.raises(TimeLimitError, match=r"the time limit of 0\.003 s was exceeded at t = ") as info:
        spacar.simulate(model, time_limit=0.003)
    res = info.value.results
    k = len(res)
    assert 0 < k < len(full)
    for name in ("t", "x", "xd", "xdd", "e", "ed", "edd", "sigma", "reaction"):
        np.testing.assert_array_equal(getattr(res, name), getattr(full, name)[:k])
    assert isinstance(info.value, SpacarError)


def test_a_failure_at_the_assembly_keeps_an_empty_result():
    text = TEXT.replace("X 8 0.45 0.", "X 8 0.45 0.\nE 3 1 -1.0")  # length -0.85 m: no assembly
    with pytest.raises(KinematicsError) as info:
        spacar.simulate(spacar.read_string(text))
    res = info.value.results
    assert len(res) == 0 and res.x.shape == (0, 13)
    assert repr(res) == "<spacar.Results: no output times, 13 coordinates, 9 deformations>"


def test_an_exception_of_the_output_callback_is_not_wrapped():
    def on_output(k, state):
        if k == 3:
            raise ZeroDivisionError("from the callback")

    with pytest.raises(ZeroDivisionError, match="from the callback") as info:
        spacar.simulate(spacar.read(EXAMPLE), on_output=on_output)
    assert not hasattr(info.value, "results")


def test_cli_time_limit(tmp_path, capsys):
    from spacar.cli import main

    path = tmp_path / "slow.dat"
    path.write_text(TEXT)
    assert main(["run", str(path), "--time-limit", "0.002"]) == 1
    err = capsys.readouterr().err
    assert re.search(r"spacar: TimeLimitError: the time limit of 0\.002 s was exceeded at t = \S+ "
                     r"\(\d+ of 101 output times computed\)", err), err


# --- the constraint diagnosis stays fast and short for large models -----------------------------

def test_the_diagnosis_of_a_large_model_is_bounded():
    start = time.perf_counter()
    model = spacar.read_string(chain(1000))  # 1000 constraints, 2000 calculable coordinates
    check = model.check()
    assert not check.diagnosis.ok and not check.diagnosis.detailed and check.diagnosis.rank == -1
    assert "constraints: not diagnosed:" in str(check)
    assert "too large for a detailed diagnosis (at most 1500 constraints and calculable coordinates)" in str(check)
    model.timestep(1, 0.1)
    with pytest.raises(KinematicsError, match="too large for a detailed diagnosis"):
        spacar.simulate(model)
    assert time.perf_counter() - start < 5.0  # was minutes: cubic SVD and selections of every column


def test_the_diagnosis_text_lists_a_bounded_number_of_items():
    check = spacar.read_string(chain(100)).check()
    d = check.diagnosis
    assert len(d.undetermined) == 100 and d.rank == 100  # the structured fields keep everything
    text = str(check)
    assert text.count("\n   - node") == 20 and "   ... and 80 more undetermined coordinates" in text
    assert text.count("free motion:") == 5 and "   ... and 95 more free motions" in text
    assert len(text) < 2000


# --- wrong types in the Python API are InputErrors (found by the fuzzing harness) ---------------

def test_wrong_types_in_the_python_api_are_input_errors():
    model = spacar.read(EXAMPLE)
    for digits in (None, 0, 18, 2.5, True, "4", 10**5000):
        with pytest.raises(InputError, match="digits must be an integer between 1 and 17"):
            model.dump(digits)
    with pytest.raises(InputError, match="on_output must be a function"):
        spacar.simulate(model.copy(), on_output=5)
    with pytest.raises(InputError, match="method must be 'dop853' or 'dopri5'"):
        spacar.simulate(model.copy(), method=None)
    with pytest.raises(InputError, match="time_limit must be a positive number of seconds"):
        spacar.simulate(model.copy(), time_limit=10**400)
    with pytest.raises(InputError, match=r"the input must be a text \(str\), got bytes: decode bytes first"):
        spacar.read_string(TEXT.encode())
    with pytest.raises(InputError, match=r"the input must be a text \(str\), got int"):
        spacar.read_string(5)
    with pytest.raises(InputError, match=r"the file name must be a str"):
        spacar.read_string(TEXT, 5)
    with pytest.raises(InputError, match=r"read: a file name or path, got 5"):
        spacar.read(5)
    with pytest.raises(InputError, match=r"cannot read the input file \(embedded null byte\)"):
        spacar.read("a\x00b")
    with pytest.raises(InputError, match=r"unknown keyword 5"):
        model.apply(5, 1)


def test_non_finite_linearized_equations_are_refused():
    model = spacar.read_string(with_lines("GRAVITY 0 -1e308"))
    # The assembly (accelerations) or the linearized matrices overflow, whichever comes first.
    with pytest.raises(SpacarError, match=r"the (accelerations|linearized equations) at t = 0 are not finite.*: "
                                          r"the model's values exceed double precision"):
        spacar.linearize(model)


def test_a_singular_velocity_block_with_an_exact_zero_pivot_is_an_error():
    """Found by fuzzing: at the identity the L2MIN1 row of a LAMBDA node with a given first
    Euler parameter is exactly zero; Eigen's condition estimate of that LU is 1, not 0, and the
    run 'succeeded' with NaN velocities."""
    text = "HINGE 1 1 2 0.1 0 0\nFIX 1\nINPUTX 1 1\nINPUTX 2 1\nRLSE 1 3\nEND\n"
    with pytest.raises(KinematicsError, match=r"constraint block is singular at t = 0\b.*\n.*rank 2"):
        spacar.simulate(spacar.read_string(text))


def test_a_second_enhc_of_a_deformation_releases_its_old_kinematic_coordinate():
    """Found by fuzzing: after ENHC 2 1 3 1 and ENHC 2 1 4 1, element 3 deformation 1 stayed a
    kinematic coordinate of nothing, and the state dump did not read back to the same model."""
    text = ("PLBEAMNL 1 1 2 3 4\nPLHINGE 2 2 4\nPLHINGE 3 4 5\nPLHINGE 4 4 5\nX 1 3.5 -3.7\nX 3 0.1 -3.5\n"
            "FIX 1\nENHC 2 1 3 1\nE 3 1 1e-3\nENHC 2 1 4 1\nEND\n")
    model = spacar.read_string(text)
    classes = {eid: [c.name for c in el.cls] for eid, el in model.elements.items()}
    assert classes[2] == ["nonholonomic"] and classes[3] == ["fixed"] and classes[4] == ["kinematic"]
    dump = model.dump(digits=17)
    assert spacar.read_string(dump).dump(digits=17) == dump
    with pytest.raises(InputError, match=r"element 4 deformation 1 is the kinematic coordinate of a nonholonomic "
                                         r"deformation \(ENHC\); change that ENHC first"):
        model.enhc(4, 1, 3, 1)


def test_non_finite_results_stop_the_run():
    """Found by fuzzing: an enormous load on a support gave infinite reactions in a run that
    'succeeded'. Now the run stops at the first such output time with a clear error."""
    text = "PLBEAMNL 1 1 2 3 4\nX 1 -1.0 2.6\nX 3 0.6 0.6\nBETA 4 100\nFIX 1\nFORCE 3 1e308 1e-300\nFIX 2 1\n"
    model = spacar.read_string(text + "TIMESTEP 2 1\nEND\n")  # the case the fuzzer found
    with pytest.raises(SpacarError, match=r"the reactions at t = 0 are not finite: the model's values exceed double "
                                          r"precision") as info:
        spacar.simulate(model)
    assert len(info.value.results) == 0
