#!/usr/bin/env python3
"""Coverage-guided fuzzing of the reader and of Results.load (issue 24) with atheris: libFuzzer
driving the Python code of spacar instrumented for its branch coverage, so that mutations which
reach new branches of the reader or of the loader are kept and mutated further. The hypothesis
harness (fuzzing.py) generates the inputs it knows how to build; this one finds the paths nobody
thought of, starting from the corpus that both keep in tests/data/fuzz/<kind>/.

The oracle is the same as the hypothesis harness's (``run_reader_file``, ``run_results_file``):
only SpacarErrors, messages that name the file and stay short, the file read as read_string reads
its text, Results of consistent shapes, each input in bounded time and memory. Anything else is a
finding: libFuzzer stops and writes the input as ``crash-<sha1>``.

    python tests/support/coverage_fuzz.py reader  -max_total_time=300   # five minutes
    python tests/support/coverage_fuzz.py results -runs=20000
    python tests/support/coverage_fuzz.py reader  -max_total_time=300 --keep

Results files are mutated inside their archive (``mutate_results``): libFuzzer's byte mutations
of a zip file rarely get past its checksums. Any libFuzzer option may follow the kind. New inputs go to a working directory (``--work DIR``,
default a temporary one); ``--keep`` then merges into the corpus those that add coverage
(libFuzzer's ``-merge=1``, which keeps the smallest input reaching each new feature). Needs the
optional package atheris (``pip install atheris``; Linux and macOS wheels).
"""
from __future__ import annotations

import argparse
import io
import os
import random
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

import atheris

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # tests/ (for `support`)
with atheris.instrument_imports(include=["spacar"]):
    import spacar  # noqa: F401  (instrumented before anything else imports it)
from support.fuzzing import CORPUS, run_reader_file, run_results_file  # noqa: E402

KINDS = ("reader", "results")
CHILD = "SPACAR_COVERAGE_FUZZ"  # set in the libFuzzer process: the kind it fuzzes
# libFuzzer's defaults for this harness: inputs as large as the corpus's, a case slower than
# 10 s or an RSS beyond 4 GB is a finding too.
DEFAULTS = ["-timeout=10", "-rss_limit_mb=4096", "-max_len=100000", "-print_final_stats=1"]


def one_input(kind: str, directory: Path):
    """The function libFuzzer calls with every input: the oracle, a Finding raised as a crash."""
    def reader(data: bytes):
        run_reader_file(data.decode("utf-8", "replace"), directory)

    def results(data: bytes):
        run_results_file(data, directory)

    return reader if kind == "reader" else results


def _members(data: bytes):
    """{name: bytes} of a small zip archive, None if it is none (or has a member over 1 MB)."""
    try:
        with zipfile.ZipFile(io.BytesIO(data)) as zf:
            infos = zf.infolist()
            if any(info.file_size > 2**20 or info.flag_bits & 0x1 for info in infos):
                return None
            return {info.filename: zf.read(info) for info in infos}
    except Exception:  # noqa: BLE001  any broken archive: mutate its bytes instead
        return None


def mutate_results(data: bytes, max_size: int, seed: int) -> bytes:
    """libFuzzer's mutation of a results file: mostly of one member inside the archive (an .npy
    header or its values, the JSON description), zipped again, so that the mutations reach the
    loader past the archive's checksums; sometimes of the archive's own bytes."""
    rng = random.Random(seed)
    members = _members(data)
    if not members or rng.random() < 0.2:
        return atheris.Mutate(data, max_size)
    name = rng.choice(sorted(members))
    if rng.random() < 0.05:
        del members[name]
    else:
        members[name] = atheris.Mutate(members[name], 2 * len(members[name]) + 64)
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", rng.choice([zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED])) as zf:
        for member, content in members.items():
            zf.writestr(member, content)
    out = buffer.getvalue()
    return out if len(out) <= max_size else data


def fuzz(kind: str) -> None:
    """libFuzzer in this process, with the arguments on the command line (flags and corpus
    directories); it exits the process when done."""
    directory = Path(tempfile.mkdtemp(prefix="spacar-coverage-fuzz-"))
    atheris.Setup(sys.argv, one_input(kind, directory),
                  custom_mutator=mutate_results if kind == "results" else None)
    atheris.Fuzz()


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("kind", choices=KINDS)
    parser.add_argument("--work", type=Path, default=None,
                        help="directory of the new inputs (default: a temporary directory)")
    parser.add_argument("--keep", action="store_true",
                        help="merge the new inputs that add coverage into tests/data/fuzz/<kind>/")
    args, libfuzzer = parser.parse_known_args(argv)
    corpus = CORPUS / args.kind
    # libFuzzer runs in a child process that gets only libFuzzer's arguments (a merge starts it
    # again with the same ones, running this file as an executable): the kind goes by the
    # environment, the interpreter first on the PATH for the file's shebang.
    env = {**os.environ, CHILD: args.kind,
           "PATH": os.pathsep.join([str(Path(sys.executable).parent), os.environ.get("PATH", "")])}
    with tempfile.TemporaryDirectory(prefix="spacar-coverage-fuzz-") as scratch:
        work = args.work or Path(scratch) / "new"
        work.mkdir(parents=True, exist_ok=True)
        status = subprocess.call([sys.executable, __file__, *DEFAULTS, *libfuzzer, str(work), str(corpus)], env=env)
        if status == 0 and args.keep:
            before = len(list(corpus.iterdir()))
            subprocess.check_call([sys.executable, __file__, *DEFAULTS, "-merge=1", str(corpus), str(work)], env=env)
            print(f"coverage_fuzz: {len(list(corpus.iterdir())) - before} inputs added to {corpus}")
    return status


if __name__ == "__main__":
    if os.environ.get(CHILD) in KINDS:
        fuzz(os.environ[CHILD])
    sys.exit(main())
