"""Time ``ar3cli lint-urdf`` as a user runs it, against the URDF checkers they would otherwise run.

Whole processes, alternating, warm-up first (see ``benchmarks/_timing.py``). Three comparisons:

1. **pybullet_data, every .urdf outside random_urdfs/ (95 files)**: ``ar3cli lint-urdf --no-cache
   <all files>`` in ONE call against the baseline, which is

   * ``check_urdf`` (``apt-get install liburdfdom-tools``) once per file, i.e. a Python loop running
     one ``check_urdf FILE`` subprocess per file, when ``check_urdf`` is on PATH (a row saying it is
     missing otherwise);
   * a small Python script that parses each file with ``urdf_parser_py`` (``URDF.from_xml_string``)
     if that is installed, else with ``yourdfpy.URDF.load(path, build_scene_graph=False,
     load_meshes=False)``: ONE process parsing every file (the baseline when check_urdf is missing);
     ``--per-file-loop`` adds the check_urdf-shaped variant, a Python loop running one such parser
     process per file (slow: one interpreter start and library import per file, ~1 minute a run
     for 95 files);
   * and, when ``urdf-validator`` is on PATH, a loop running ``urdf-validator FILE`` once per file.

   The output says which baseline ran. The baselines only parse (structure, kinematic tree);
   lint-urdf runs all its rules and reads every mesh's bounding box.
2. **one file, pybullet_data's franka_panda/panda.urdf** (18 OBJ meshes): ``ar3cli lint-urdf
   --no-cache panda.urdf`` (a fresh process; the mesh boxes are cached by the warm-up, the file is
   checked again) against one baseline call (``check_urdf panda.urdf`` itself when installed, and
   one run of the Python parser script), with ``python -c pass`` for scale.
3. **the whole pybullet_data folder** (1,095 URDF files in pybullet 3.2.7, ``random_urdfs/``
   included), ``ar3cli lint-urdf <folder>`` with an empty ar3cli cache and with its results cached.
4. **example-robot-data, 40 robots** spread evenly over its sorted URDF list: ``ar3cli lint-urdf
   --no-cache <40 files>`` with an EMPTY ar3cli cache (``AR3CLI_CACHE_DIR`` a fresh folder per run:
   every mesh is read and parsed) against the same with the mesh cache warm, and a plain re-run
   (results cached: nothing changed since the last run). Needs example-robot-data in
   ``~/.cache/ar3cli-sweep/erd`` (``--erd DIR``; install it with ``pip install --no-deps --target
   ~/.cache/ar3cli-sweep/erd example-robot-data``, ~400 MB, as the real-robot sweep does); skipped
   with a message when it is missing.

ar3cli exits 1 when a file has errors (many of these files have some): exit 0 and 1 both count as a
completed run. The OS file cache is warm in every run (warm-up), so "empty cache" means ar3cli's
own cache only.

Usage (inside the project's venv)::

    python benchmarks/bench_lint.py                 # 5 runs each, ~3 minutes on 2 cores
    python benchmarks/bench_lint.py --runs 9 --per-file-loop
    python benchmarks/bench_lint.py --skip-erd --erd-count 20
"""

from __future__ import annotations

import argparse
import itertools
import shutil
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import _timing  # noqa: E402 - after the sys.path line that finds it

DEFAULT_ERD = Path("~/.cache/ar3cli-sweep/erd/cmeel.prefix/share/example-robot-data/robots").expanduser()

LOOP = r'''
"""Run one checker process per file, as a shell loop would (exit codes ignored: findings are fine)."""
import subprocess, sys
separator = sys.argv.index("--")
command, files = sys.argv[1:separator], sys.argv[separator + 1:]
for path in files:
    subprocess.run([*command, path], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
'''

PARSE = r'''
"""Parse each URDF given on the command line with {library}; print how many parsed."""
import sys
{imports}
ok, failed = 0, []
for path in sys.argv[1:]:
    try:
        {parse}
        ok += 1
    except Exception as exc:  # a file the library refuses is still a completed check
        failed.append(f"{{path}}: {{type(exc).__name__}}: {{exc}}"[:200])
print(f"{{ok}} parsed, {{len(failed)}} refused")
for line in failed:
    print(line)
sys.exit(1 if failed else 0)
'''


def parser_baseline() -> tuple[str, Path]:
    """(library name, script path) of the Python parsing baseline used when check_urdf is missing."""
    try:
        import urdf_parser_py.urdf  # noqa: F401 - probing only
    except ImportError:
        library = "yourdfpy"
        imports = "import yourdfpy"
        parse = "yourdfpy.URDF.load(path, build_scene_graph=False, load_meshes=False)"
    else:
        library = "urdf_parser_py"
        imports = "from urdf_parser_py.urdf import URDF"
        parse = "URDF.from_xml_string(open(path, 'rb').read())"
    script = _timing.write_script("parse_urdf.py", PARSE.format(library=library, imports=imports, parse=parse))
    return library, script


def baselines(files: list[Path], per_file_loop: bool) -> tuple[list[_timing.Variant], list[str]]:
    """The baseline variants for ``files`` and notes saying which ran."""
    loop = _timing.write_script("loop.py", LOOP)
    paths = list(map(str, files))
    variants, notes = [], []
    check_urdf = shutil.which("check_urdf")
    single = len(files) == 1
    if check_urdf and single:
        variants.append(_timing.Variant(f"`check_urdf {files[0].name}`", [check_urdf, paths[0]], ok_codes=(0, 1)))
        notes.append(f"check_urdf baseline: {check_urdf}, called directly")
    elif check_urdf:
        variants.append(_timing.Variant("`check_urdf FILE`, once per file (a Python loop)",
                                        [sys.executable, str(loop), check_urdf, "--", *paths]))
        notes.append(f"check_urdf baseline: {check_urdf}, one process per file")
    else:
        notes.append("check_urdf is not installed (apt-get install liburdfdom-tools): no check_urdf row; "
                     "the Python parser below is the baseline")
    library, script = parser_baseline()
    variants.append(_timing.Variant(f"Python script parsing {'the file' if single else 'every file'} with "
                                    f"{library}, one process",
                                    [sys.executable, str(script), *paths], ok_codes=(0, 1)))
    notes.append(f"Python baseline: one process parsing each file with {library}"
                 + ("" if library == "urdf_parser_py" else
                    " (urdf_parser_py is not installed: yourdfpy.URDF.load(path, build_scene_graph=False, "
                    "load_meshes=False))"))
    if per_file_loop:
        variants.append(_timing.Variant(f"{library} parser, one process per file (a Python loop)",
                                        [sys.executable, str(loop), sys.executable, str(script), "--", *paths]))
    elif len(files) > 1:
        notes.append(f"the {library} parser as one process per file (like check_urdf) was not run: --per-file-loop")
    validator = shutil.which("urdf-validator")
    if validator and single:
        variants.append(_timing.Variant(f"`urdf-validator {files[0].name}`", [validator, paths[0]],
                                        ok_codes=tuple(range(256))))
        notes.append(f"urdf-validator: {validator}")
    elif validator:
        variants.append(_timing.Variant("`urdf-validator FILE`, once per file (a Python loop)",
                                        [sys.executable, str(loop), validator, "--", *paths]))
        notes.append(f"urdf-validator: {validator}")
    else:
        notes.append("urdf-validator is not installed: no row for it")
    return variants, notes


def check_urdf_ratio(comparison: _timing.Comparison) -> str:
    """The line saying lint-urdf's wall time over the check_urdf loop's, round by round (issue 29: <= 1.0)."""
    ours = comparison.variants[0]
    loop = next((variant for variant in comparison.variants if variant.name.startswith("`check_urdf")), None)
    if loop is None:
        return "ratio lint-urdf / check_urdf loop: not measured (check_urdf is not installed)"
    ratios = [mine.wall / theirs.wall for mine, theirs in zip(ours.runs, loop.runs)]
    return (f"**ratio: lint-urdf / the check_urdf loop, wall, round by round: median {statistics.median(ratios):.2f}** "
            f"(issue 29's target: <= 1.0; per round: {' '.join(f'{value:.2f}' for value in ratios)})")


def erd_files(root: Path, count: int) -> list[Path]:
    """``count`` URDFs spread evenly over example-robot-data's sorted list (all if it has fewer)."""
    every = sorted(root.rglob("*.urdf"))
    if len(every) <= count:
        return every
    return [every[round(i * (len(every) - 1) / (count - 1))] for i in range(count)] if count > 1 else every[:1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5, help="timed runs of each variant (default 5)")
    parser.add_argument("--per-file-loop", action="store_true",
                        help="without check_urdf: also time one Python parser process per file (~1 min a run)")
    parser.add_argument("--erd", type=Path, default=DEFAULT_ERD,
                        help=f"example-robot-data's robots/ folder (default {DEFAULT_ERD})")
    parser.add_argument("--erd-count", type=int, default=40, help="example-robot-data robots to lint (default 40)")
    parser.add_argument("--skip-erd", action="store_true", help="skip the example-robot-data comparison")
    args = parser.parse_args()

    data = _timing.pybullet_data_path()
    models = sorted(path for path in data.rglob("*.urdf") if "random_urdfs" not in path.relative_to(data).parts)
    panda = data / "franka_panda" / "panda.urdf"
    lint = [*_timing.ar3cli_command(), "lint-urdf"]
    print(_timing.machine_header("lint-urdf"))
    try:
        variants, notes = baselines(models, args.per_file_loop)
        ours = _timing.Variant(f"`ar3cli lint-urdf --no-cache <{len(models)} files>`, one call",
                               [*lint, "--no-cache", *map(str, models)], ok_codes=(0, 1))
        comparison = _timing.measure(f"pybullet_data: {len(models)} URDF files (random_urdfs/ excluded)",
                                     [ours, *variants], args.runs, notes=notes)
        comparison.notes.insert(0, check_urdf_ratio(comparison))
        print(_timing.table(comparison))

        variants, notes = baselines([panda], per_file_loop=False)
        ours = _timing.Variant("`ar3cli lint-urdf --no-cache panda.urdf`", [*lint, "--no-cache", str(panda)],
                               ok_codes=(0, 1))
        floor = _timing.Variant("`python -c pass` (interpreter start-up, for scale)", [sys.executable, "-c", "pass"])
        print(_timing.table(_timing.measure("one file: franka_panda/panda.urdf, a fresh process",
                                            [ours, *variants, floor], args.runs, notes=notes)))

        every = sum(1 for _ in data.rglob("*.urdf"))
        empties = itertools.count()

        def empty_cache_folder() -> dict[str, str]:
            return {"AR3CLI_CACHE_DIR": str(_timing.WORK / f"whole-{next(empties)}")}

        whole = [*lint, str(data)]
        print(_timing.table(_timing.measure(
            f"the whole pybullet_data folder ({every:,} URDF files, random_urdfs/ included), one call", [
                _timing.Variant("empty ar3cli cache (a fresh AR3CLI_CACHE_DIR each run)", whole,
                                prepare=empty_cache_folder, ok_codes=(0, 1)),
                _timing.Variant("cached (files unchanged since the warm-up)", whole, ok_codes=(0, 1)),
            ], args.runs)))

        if args.skip_erd:
            pass
        elif not args.erd.is_dir():
            print(f"### example-robot-data\n\nskipped: {args.erd} does not exist (install it with "
                  f"`pip install --no-deps --target ~/.cache/ar3cli-sweep/erd example-robot-data`, or give --erd)\n")
        else:
            files = erd_files(args.erd, args.erd_count)
            fresh = itertools.count()

            def empty_cache() -> dict[str, str]:
                folder = _timing.WORK / f"empty-cache-{next(fresh)}"
                previous = _timing.WORK / f"empty-cache-{int(folder.name.rsplit('-', 1)[1]) - 1}"
                shutil.rmtree(previous, ignore_errors=True)
                return {"AR3CLI_CACHE_DIR": str(folder)}

            command = [*lint, "--no-cache", *map(str, files)]
            variants = [
                _timing.Variant("mesh cache EMPTY (fresh AR3CLI_CACHE_DIR each run), --no-cache", command,
                                prepare=empty_cache, ok_codes=(0, 1)),
                _timing.Variant("mesh cache warm, --no-cache (every file checked again)", command, ok_codes=(0, 1)),
                _timing.Variant("re-run, results cached (no --no-cache, files unchanged)",
                                [*lint, *map(str, files)], ok_codes=(0, 1)),
            ]
            names = ", ".join(path.stem for path in files)
            comparison = _timing.measure(
                f"example-robot-data: `ar3cli lint-urdf` on {len(files)} robots, one call", variants, args.runs,
                notes=[f"robots: {names}"])
            comparison.notes.insert(0, f"**empty mesh cache: median {variants[0].wall:.2f} s** (issue 29: keep the "
                                       "1.7-2.2 s measured before it)")
            print(_timing.table(comparison))
        print(_timing.machine_footer())
    finally:
        _timing.cleanup()


if __name__ == "__main__":
    main()
