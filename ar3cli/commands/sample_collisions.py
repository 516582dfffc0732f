"""``ar3cli sample-collisions``: the self-collision matrix, MoveIt-style, with statistics."""

from pathlib import Path
from typing import Annotated, Optional

import typer

from ar3cli.commands.options import (
    FollowSymlinksOption,
    FormatOption,
    RobotPathArgument,
    SeedOption,
    TimeoutOption,
    finite_float,
    samples_option,
)
from ar3cli.commands.robot_options import RobotSource, robot_input
from ar3cli.errors import UserError
from ar3cli.infra.child_limits import LONG_TIMEOUT_S

SamplesOption = Annotated[int, samples_option("Uniform random configurations to check (MoveIt's default: 10000).",
                                              most=10_000_000)]
JobsOption = Annotated[Optional[int], typer.Option(
    "--jobs", "-j", min=1, show_default=False,
    help="Processes that share the samples, at most one per CPU (forked copies of the loaded model). Default "
         "on Linux: one per 2000 samples, at most one per CPU; elsewhere 1. The counts are exact and the same "
         "for any value.")]
ThresholdOption = Annotated[float, typer.Option("--always-threshold", click_type=finite_float(0.01, 1.0),
                                                help="A pair in contact in at least this fraction of samples "
                                                     "is 'always' colliding.")]
SrdfOption = Annotated[Optional[Path], typer.Option("--srdf", metavar="OUT", dir_okay=False,
                                                    help="Write MoveIt `<disable_collisions>` entries to this "
                                                         "SRDF file (with --srdf-merge: the merged SRDF).")]
SrdfMergeOption = Annotated[Optional[Path], typer.Option(
    "--srdf-merge", metavar="EXISTING.srdf", dir_okay=False, show_default=False,
    help="Merge the disabled pairs into a copy of this SRDF, written to --srdf OUT, which is required: give "
         "the same path to update the file in place (atomically). Only `<disable_collisions>` with reason "
         "Adjacent, Default, Always or Never (what MoveIt Setup Assistant and ar3cli write) are replaced; "
         "groups, group states, end effectors, virtual and passive joints, comments and pairs with any "
         "other reason stay byte for byte.")]
SrdfCompareOption = Annotated[Optional[Path], typer.Option(
    "--srdf-compare", metavar="EXISTING.srdf", dir_okay=False, show_default=False,
    help="Compare this SRDF with the sampled matrix: pairs it disables that do collide (dangerous), pairs "
         "it leaves enabled that MoveIt would disable (missing) or that never collide (wasted), entries "
         "naming links the URDF lacks (unknown); the matrix table marks the pairs it disables.")]
PngOption = Annotated[Optional[Path], typer.Option("--png", metavar="OUT.png", dir_okay=False,
                                                 help="Draw the pair matrix as a heat map picture.")]
FilterOption = Annotated[Optional[Path], typer.Option("--pybullet-filter", metavar="OUT", dir_okay=False,
                                                      help="Write the disabled pairs as JSON for PyBullet's "
                                                           "setCollisionFilterPair.")]


@robot_input
def sample_collisions(
    path: RobotPathArgument,
    source: RobotSource,
    samples: SamplesOption = 10_000,
    seed: SeedOption = 0,
    jobs: JobsOption = None,
    always_threshold: ThresholdOption = 0.95,
    srdf: SrdfOption = None,
    srdf_merge: SrdfMergeOption = None,
    srdf_compare: SrdfCompareOption = None,
    pybullet_filter: FilterOption = None,
    png: PngOption = None,
    follow_symlinks: FollowSymlinksOption = False,
    format: FormatOption = "text",
    timeout: TimeoutOption = LONG_TIMEOUT_S,
) -> None:
    """Sample joint configurations and classify every link pair as MoveIt Setup Assistant does.

    Pairs are adjacent / default (touching at home) / always / never / sometimes; 'never' comes with
    the 95% upper bound on its collision probability, 'sometimes' with a Wilson 95% interval. The
    home pose and every driving joint at its limits (mimic joints follow) are checked too; a link and
    its direct parent are adjacent and not sampled. Exit 0 when the matrix was computed.
    """
    # Only what the pybullet child needs is imported before it is forked; the report's modules are
    # imported while it samples (``_report_modules``), the SRDF and output modules only when asked for.
    from ar3cli.collisions.run import sample_matrix

    if srdf_merge is not None and srdf is None:
        raise UserError(f"--srdf-merge {srdf_merge}: give --srdf OUT for the merged SRDF (the same path "
                        "updates the file in place)")
    _check_outputs(srdf, pybullet_filter, png, follow_symlinks)
    existing = reference = None
    if srdf_merge is not None:
        from ar3cli.collisions import srdf_files

        existing = srdf_files.read_for_merge(srdf_merge)
    if srdf_compare is not None:
        from ar3cli.urdf.srdf_read import read_srdf

        same = existing is not None and srdf_compare.resolve() == srdf_merge.resolve()
        reference = existing if same else read_srdf(srdf_compare)
    model = source.load(path)
    run = sample_matrix(model, samples, seed, jobs, always_threshold, meanwhile=lambda: _report_modules(format))
    from ar3cli.collisions import matrix as cm
    from ar3cli.collisions import srdf_files
    from ar3cli.collisions.matrix_report import matrix_report
    from ar3cli.output.formats import finish
    comment = (f"generated by ar3cli sample-collisions: {samples} samples, seed {seed}, "
               f"always threshold {always_threshold}")
    merged = None
    if srdf is not None and existing is not None:
        merged = srdf_files.merge(existing, run.results, comment)
        merged.target = srdf
        _write(follow_symlinks, srdf, merged.data)
    elif srdf is not None:
        _write(follow_symlinks, srdf, srdf_files.srdf_bytes(model.name or "robot", run.results, comment))
    if pybullet_filter is not None:
        _write(follow_symlinks, pybullet_filter, cm.pybullet_filter_bytes(run.results, comment))
    if png is not None:
        from ar3cli.collisions.heatmap_png import heat_map_png

        _write(follow_symlinks, png, heat_map_png(run.links, run.pairs, run.results,
                                 title=f"{model.name or model.path.name}: {samples} samples, seed {seed}"))
    comparison = None
    if reference is not None:
        comparison = srdf_files.compare(reference, run.results, [link.name for link in model.links])
    finish(matrix_report(model, run, format, comparison=comparison, merged=merged), format)


def _report_modules(format: str) -> None:
    """Import what the report in ``format`` needs, while the pybullet child samples: then it costs no
    wall time (measured on the panda: the report's modules, and rich's for the heat map, took ~45 ms
    after the child; rich's emoji table alone ~13 ms, loaded at the first line printed). A module
    that is missing (rich reorganised) or fails to import is imported again later, where it is used and
    its error can be reported, or not at all: a warm-up never ends a run whose sampling went well."""
    import contextlib
    import importlib

    modules = ["ar3cli.collisions.matrix_report", "ar3cli.output.formats"]
    if format != "json":  # the heat map is a rich renderable: text output goes through a rich console
        modules += ["rich.console", "rich.text", "rich.table", "rich.box", "rich.padding", "rich._emoji_codes"]
    for module in modules:
        with contextlib.suppress(Exception):  # a warm-up only: what fails here fails again where it is used
            importlib.import_module(module)


def _check_outputs(srdf: Path | None, pybullet_filter: Path | None, png: Path | None,
                   follow_symlinks: bool) -> None:
    """Refuse unusable output paths before minutes of sampling, not after."""
    if png is not None and png.suffix.lower() != ".png":
        raise UserError(f"--png {png}: the file name must end in .png")
    targets = [target for target in (srdf, pybullet_filter, png) if target is not None]
    if targets:
        from ar3cli.infra.atomic import check_writable

        for target in targets:
            check_writable(target, follow_symlinks)


def _write(follow_symlinks: bool, path: Path, data: bytes) -> None:
    from ar3cli.infra.atomic import atomic_write

    atomic_write(path, data, follow_symlinks=follow_symlinks)
