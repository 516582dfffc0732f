"""How ``ar3cli lint-urdf`` time grows with the number of links: chains and stars of 1k..32k links.

A hostile pull request can be a small file with many links (a 3,000-link chain is 300 KB). Every rule
must stay near-linear in the links and joints: this benchmark generates chains (each link hangs from
the previous one: depth = links) and stars (every link hangs from the root: one parent with thousands
of children), each link with an inertial, a box, a mesh reference that does not resolve, a material,
a continuous joint without limits (J011 walks what hangs below), every tenth joint a mimic, a
transmission and a ``<gazebo reference>``, and an inline ``ar3cli: ignore`` comment on every fifth
link, so most rules have work and findings. Each size is linted by a whole process, ``ar3cli
lint-urdf --no-cache --format json FILE`` (see ``benchmarks/_timing.py``; one warm-up process first, then the median of
``--runs``), and the table shows the time per size and the growth per doubling (time(2n) / time(n);
linear = 2.0, quadratic = 4.0).

Usage (inside the project's venv)::

    python benchmarks/bench_growth.py                    # 1k..8k links, 3 runs each, ~40 s on 2 cores
    python benchmarks/bench_growth.py --max-links 32000 --runs 1  # the full table, ~1.5 minutes
    python benchmarks/bench_growth.py --write-only DIR   # just write the generated files
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import _timing  # noqa: E402 - after the sys.path line that finds it

SHAPES = ("chain", "star")


def robot(shape: str, links: int) -> str:
    """A URDF of ``links`` links, each one's parent the previous link (chain) or the root (star)."""
    lines = ['<?xml version="1.0"?>', '<robot name="growth">',
             '<material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>',
             '<link name="l0"><visual><geometry><box size="0.2 0.2 0.2"/></geometry></visual></link>']
    for index in range(1, links):
        parent = f"l{index - 1}" if shape == "chain" else "l0"
        ignore = "<!-- ar3cli: ignore[G002] -->" if index % 5 == 0 else ""
        lines.append(
            f'<link name="l{index}">{ignore}<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" '
            'ixy="0" ixz="0" iyz="0"/></inertial><visual><geometry><mesh filename="package://nowhere/part.stl"/>'
            '</geometry><material name="grey"/></visual><collision><geometry><box size="0.1 0.1 0.1"/></geometry>'
            '</collision></link>')
        mimic = f'<mimic joint="j{index - 1}"/>' if index % 10 == 0 and index > 1 else ""
        lines.append(f'<joint name="j{index}" type="continuous"><parent link="{parent}"/><child link="l{index}"/>'
                     f'<origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>{mimic}</joint>')
        if index % 10 == 0:
            lines.append(f'<transmission name="t{index}"><type>transmission_interface/SimpleTransmission</type>'
                         f'<joint name="j{index}"/><actuator name="m{index}"/></transmission>')
            lines.append(f'<gazebo reference="l{index}"><mu1>0.5</mu1></gazebo>')
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


def sizes(max_links: int) -> list[int]:
    found, size = [], 1000
    while size <= max_links:
        found.append(size)
        size *= 2
    return found


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--max-links", type=int, default=8000, help="largest robot (sizes double from 1,000)")
    parser.add_argument("--runs", type=int, default=3, help="timed runs per file")
    parser.add_argument("--shapes", default="chain,star", help="comma-separated: chain, star")
    parser.add_argument("--write-only", type=Path, help="write the generated files into this folder and stop")
    args = parser.parse_args()
    shapes = [shape.strip() for shape in args.shapes.split(",") if shape.strip()]
    if not set(shapes) <= set(SHAPES) or not sizes(args.max_links):
        raise SystemExit(f"--shapes takes {', '.join(SHAPES)}; --max-links at least 1000")
    folder = args.write_only or _timing.WORK / "robots"
    folder.mkdir(parents=True, exist_ok=True)
    files = {}
    for shape in shapes:
        for size in sizes(args.max_links):
            path = folder / f"{shape}_{size}.urdf"
            path.write_text(robot(shape, size))
            files[shape, size] = path
    if args.write_only:
        print("\n".join(str(path) for path in files.values()))
        return

    print(_timing.machine_header("lint-urdf growth: chains and stars"))
    lines = ["| shape | links | file KB | wall s | CPU s | growth per doubling, wall | growth per doubling, CPU |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    worst = {"wall": 0.0, "cpu": 0.0}

    def variant(shape: str, size: int) -> _timing.Variant:
        return _timing.Variant(f"{shape} {size}", [*_timing.ar3cli_command(), "lint-urdf", "--no-cache", "--format",
                                                   "json", str(files[shape, size])], ok_codes=(0, 1))

    # One warm-up process compiles every module (the bytecode cache) and fills the OS file cache; the
    # large files need no warm-up of their own (their time is the work, and it would double the run).
    variant(shapes[0], 1000).run()
    for shape in shapes:
        previous: _timing.Variant | None = None
        for size in sizes(args.max_links):
            timed = variant(shape, size)
            _timing.measure(f"{shape} of {size} links", [timed], args.runs, warmup=False)
            growth = {"wall": "", "cpu": ""}
            if previous is not None:
                for key in growth:
                    ratio = getattr(timed, key) / max(getattr(previous, key), 1e-9)
                    worst[key] = max(worst[key], ratio)
                    growth[key] = f"{ratio:.2f}x"
            lines.append(f"| {shape} | {size:,} | {files[shape, size].stat().st_size // 1024:,} | {timed.wall:.2f} "
                         f"| {timed.cpu:.2f} | {growth['wall']} | {growth['cpu']} |")
            previous = timed
    print("\n".join(lines))
    print(f"\nworst growth per doubling: wall {worst['wall']:.2f}x, CPU {worst['cpu']:.2f}x (linear 2.0, quadratic "
          "4.0; CPU time is the steadier measure on a shared machine)\n")
    print(_timing.machine_footer())


if __name__ == "__main__":
    main()
