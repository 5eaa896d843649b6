"""Issue 24, finding 4: `Results.load` checks its file before trusting it.

Every malformed file ends in an InputError naming the file; the arrays' sizes are read from
their .npy headers and checked against spacar.memory_limit() before anything is decompressed
(a small file that inflates beyond the limit is refused at once).
"""
import io
import json
import os
import time
import zipfile

import numpy as np
import pytest

import spacar
from spacar import Results
from support.paths import EXAMPLES


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    model = spacar.read(EXAMPLES / "slidercrank.dat")
    model.apply("LINEAR", 1)
    model.apply("TIMESTEP", 3, 0.1)
    path = tmp_path_factory.mktemp("load") / "good.npz"
    spacar.simulate(model, progress=False).save(path)
    return path


def members(path):
    with np.load(path, allow_pickle=False) as f:
        return {name: f[name] for name in f.files}


def write(path, arrays, **raw):
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    with zipfile.ZipFile(buf, "a") as zf:
        for name, data in raw.items():
            zf.writestr(name, data)
    path.write_bytes(buf.getvalue())
    return path


def refused(path, match):
    with pytest.raises(spacar.InputError, match=match) as info:
        Results.load(path)
    assert str(path) in str(info.value)
    assert len(str(info.value)) < 500
    return info.value


def test_the_good_file_loads(saved):
    res = Results.load(saved)
    assert len(res) == 4 and len(res.linearizations) == 4


def meta_with(saved, **changes):
    arrays = members(saved)
    meta = json.loads(str(arrays["meta"]))
    meta.update(changes)
    arrays["meta"] = np.array(json.dumps(meta))
    return arrays


@pytest.mark.parametrize("case, match", [
    ("empty", "not a valid spacar results file"),
    ("text", "not a valid spacar results file"),
    ("truncated", "not a valid spacar results file"),
    ("missing x", "array 'x' is missing"),
    ("string x", "array 'x' has the type <U"),
    ("complex e", "array 'e' has the type complex"),
    ("short x", r"array 'x' has the shape \(3, 13\), expected \(4, 13\)"),
    ("3-d labels", r"coordinate_labels' has the shape"),
    ("float labels", "coordinate_labels' has the type float"),
    ("huge labels", "numbers out of range"),
    ("object array", "holds Python objects|not a valid"),
    ("no meta", "no description"),
    ("meta not json", "not a valid spacar results file"),
    ("meta a list", "not a spacar results file"),
    ("meta deep", "not a valid spacar results file|malformed"),
    ("stats a list", "'stats' is malformed"),
    ("linearizations wrong", "'linearizations' is malformed"),
    ("lin matrix shape", r"lin0_M0' has the shape"),
    ("extra member", "unexpected member"),
    ("extra lin array", "unexpected array"),
    ("bad geometry", "not a valid spacar results file"),
    ("dof label", "."),
    ("unterminated header", r"x.npy: not a valid .npy header \(TokenError"),
    ("encrypted member", r"\.npy is encrypted"),
    ("lin matrix nan", r"'lin0_K0' holds values that are not finite"),
    ("meta beyond unicode", r"the description 'meta' holds invalid characters"),
])
def test_malformed_files_are_input_errors(saved, tmp_path, case, match):
    path = tmp_path / "bad.npz"
    good = members(saved)
    if case == "empty":
        path.write_bytes(b"")
    elif case == "text":
        path.write_text("hello")
    elif case == "truncated":
        path.write_bytes(saved.read_bytes()[:2000])
    elif case == "missing x":
        write(path, {k: v for k, v in good.items() if k != "x"})
    elif case == "string x":
        write(path, {**good, "x": good["x"].astype(str)})
    elif case == "complex e":
        write(path, {**good, "e": good["e"].astype(complex)})
    elif case == "short x":
        write(path, {**good, "x": good["x"][:3]})
    elif case == "3-d labels":
        write(path, {**good, "coordinate_labels": good["coordinate_labels"][:, :, None]})
    elif case == "float labels":
        write(path, {**good, "coordinate_labels": good["coordinate_labels"].astype(float)})
    elif case == "huge labels":
        write(path, {**good, "coordinate_labels": good["coordinate_labels"] * 2**40})
    elif case == "object array":
        buf = io.BytesIO()
        np.save(buf, np.array([{"a": 1}], dtype=object), allow_pickle=True)
        write(path, {k: v for k, v in good.items() if k != "t"}, **{"t.npy": buf.getvalue()})
    elif case == "no meta":
        write(path, {k: v for k, v in good.items() if k != "meta"})
    elif case == "meta not json":
        write(path, {**good, "meta": np.array("{not json")})
    elif case == "meta a list":
        write(path, {**good, "meta": np.array("[1, 2]")})
    elif case == "meta deep":
        write(path, {**good, "meta": np.array("[" * 100000 + "]" * 100000)})
    elif case == "stats a list":
        write(path, meta_with(saved, stats=[1]))
    elif case == "linearizations wrong":
        write(path, meta_with(saved, linearizations=[{"t": "a"}]))
    elif case == "lin matrix shape":
        write(path, {**good, "lin0_M0": np.zeros((2, 3))})
    elif case == "extra member":
        write(path, good, **{"payload.bin": b"123"})
    elif case == "extra lin array":
        write(path, {**good, "lin99_M0": np.zeros((2, 2))})
    elif case == "bad geometry":
        write(path, meta_with(saved, geometry={"nodes": 5}))
    elif case == "dof label":
        write(path, meta_with(saved, dof_labels=["x(99,1)"]))
    elif case == "unterminated header":  # found by the coverage-guided fuzzing: numpy's filter raised TokenError
        header = b"{'descr': '<f8', 'fortran_order': False, 'shape': (1000"
        write(path, {k: v for k, v in good.items() if k != "x"},
              **{"x.npy": b"\x93NUMPY\x01\x00" + len(header).to_bytes(2, "little") + header})
    elif case == "encrypted member":  # found by the coverage-guided fuzzing: zipfile raised RuntimeError
        write(path, good)
        data = bytearray(path.read_bytes())
        for signature, offset in ((b"PK\x03\x04", 6), (b"PK\x01\x02", 8)):  # local and central headers
            at = data.find(signature)
            while at >= 0:
                data[at + offset] |= 0x1
                at = data.find(signature, at + 4)
        path.write_bytes(bytes(data))
    elif case == "lin matrix nan":  # found by the coverage-guided fuzzing: eigenfrequencies() raised ValueError
        write(path, {**good, "lin0_K0": np.full_like(good["lin0_K0"], np.nan)})
    elif case == "meta beyond unicode":  # found by the coverage-guided fuzzing: json raised SystemError
        codes = np.frombuffer(str(good["meta"]).encode("utf-32-le"), "<u4").copy()
        codes[3] = 0x7FFFFFFF
        write(path, {**good, "meta": codes.view(f"<U{codes.size}").reshape(())})
    refused(path, match)


def test_wrong_path_types_and_non_files(tmp_path):
    for bad in (3, None, 2.5, ["a"]):
        with pytest.raises(spacar.InputError, match="Results.load: path must be a file name or path"):
            Results.load(bad)
    refused(tmp_path / "missing.npz", "cannot read the results file")
    refused(tmp_path, "not a regular file")
    if hasattr(os, "mkfifo"):
        os.mkfifo(tmp_path / "fifo.npz")
        refused(tmp_path / "fifo.npz", "not a regular file")  # at once, not blocking


def test_a_compression_bomb_is_refused_before_decompressing(saved, tmp_path):
    good = members(saved)
    n = 4 * 10**7  # 320 MB of zeros: about 0.3 MB compressed
    bomb = {**good, "t": np.zeros(n), **{k: np.zeros((n, good[k].shape[1])) for k in ()}}
    path = tmp_path / "bomb.npz"
    buf = io.BytesIO()
    np.savez_compressed(buf, **bomb)
    path.write_bytes(buf.getvalue())
    assert path.stat().st_size < 2 * 10**6
    limit = spacar.memory_limit()
    spacar.set_memory_limit(100 * 2**20)
    try:
        start = time.perf_counter()
        err = refused(path, r"would need 0\.32 GB, more than the memory limit")
        assert time.perf_counter() - start < 1.0, err
    finally:
        spacar.set_memory_limit(limit)
    # under the default limit the shapes, also read from the headers, refuse it before inflating
    start = time.perf_counter()
    refused(path, r"array 'x' has the shape \(4, 13\), expected \(40000000, 13\)")
    assert time.perf_counter() - start < 1.0


def test_concatenate_checks_its_argument(saved):
    res = Results.load(saved)
    assert len(Results.concatenate([res, res])) == 8
    for bad, match in ((["a"], r"results\[0\] is not a spacar.Results, got 'a'"), (3, "list of spacar.Results"),
                       (res, "list of spacar.Results"), ([res, None], r"results\[1\]")):
        with pytest.raises(spacar.InputError, match=match):
            Results.concatenate(bad)
