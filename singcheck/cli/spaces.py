"""``singcheck workspace`` and ``singcheck jointspace``: solution counts by region.

Registered on the main group by :mod:`singcheck.cli`; the work is done by
:mod:`singcheck.space_analysis`, the rendering by :mod:`singcheck.space_report`.
"""

from __future__ import annotations

import sys
from fractions import Fraction

import click

from singcheck.cli.exitcodes import ExitCode
from singcheck.report.progress import Progress

BACKENDS = ["auto", "singular", "macaulay2", "sympy", "flint"]


def parse_slice(text: str) -> tuple[str, Fraction]:
    """``AXIS=VALUE`` with an exact rational VALUE, parsed by singcheck's own grammar."""
    from singcheck.spec.grammar import ExprError, compile_constant, parse

    axis, sep, value = text.partition("=")
    axis = axis.strip()
    if not sep or not axis or not value.strip():
        raise click.BadParameter(f"{text!r}: write AXIS=VALUE, e.g. z=1 or z=1/2",
                                 param_hint="--slice")
    try:
        number = compile_constant(parse(value))
    except ExprError as e:
        raise click.BadParameter(f"{text!r}: {e}", param_hint="--slice") from None
    if number.pi_coefficient:
        raise click.BadParameter(f"{text!r}: the value must be rational (no pi)",
                                 param_hint="--slice")
    return axis, number.rational


def _slices(values) -> dict[str, Fraction]:
    out: dict[str, Fraction] = {}
    for text in values:
        axis, value = parse_slice(text)
        if axis in out:
            raise click.BadParameter(f"{axis} is sliced twice", param_hint="--slice")
        out[axis] = value
    return out


def _options(space: str):
    axes = "pose" if space == "workspace" else "joint"

    def decorate(f):
        for option in reversed([
            click.argument("robot", type=click.Path(dir_okay=False)),
            click.option("--slice", "slices", multiple=True, metavar="AXIS=VALUE",
                         help=f"Fix a {axes} axis to an exact rational (repeatable): the "
                         "decomposition is then of that slice."),
            click.option("--surfaces", type=click.Choice(["auto", "all", "counts"]),
                         default="auto", show_default=True,
                         help="all: the whole discriminant variety; counts: only the "
                         "surfaces across which the count can change; auto: all in a "
                         "plane, counts in 3-D."),
            click.option("--no-limits", is_flag=True,
                         help="Ignore the joint limits: count every real solution."),
            click.option("--backend", type=click.Choice(BACKENDS), default="auto",
                         envvar="SINGCHECK_BACKEND", show_default=True,
                         help="Elimination backend for ξ, ε and the serial projections."),
            click.option("--timeout", type=click.FloatRange(min=0, min_open=True),
                         default=600, show_default=True,
                         help="Seconds an external backend may run."),
            click.option("--no-cache", is_flag=True, help="Do not read or write the "
                         "elimination cache."),
            click.option("--time-limit", type=click.FloatRange(min=0, min_open=True),
                         default=300, show_default=True,
                         help="Seconds allowed to the analysis (the discriminant variety, "
                         "the decomposition, the counts and the regions; a CAS run is "
                         "also bounded by --timeout); past it the command ends with exit "
                         "3, unknown: time limit, and writes nothing."),
            click.option("--format", "fmt", type=click.Choice(["table", "json"]),
                         default="table", show_default=True),
            click.option("-o", "--output", type=click.Path(dir_okay=False, writable=True),
                         help="Write the report here (atomically) instead of stdout."),
            click.option("-q", "--quiet", is_flag=True, help="No progress notes on stderr."),
            click.option("-v", "--verbose", is_flag=True,
                         help="List every region, outside ones included."),
        ]):
            f = option(f)
        return f

    return decorate


def compute(space: str, robot: str, slices, surfaces: str, no_limits: bool, backend: str,
            timeout: float, no_cache: bool, progress, time_limit: float | None = None):
    """The analysis and the labels of the surfaces left out (shared with ``plot``), within
    ``time_limit`` seconds (:class:`~singcheck.budget.TimeLimitExceeded` past it)."""
    from singcheck.budget import deadline

    with deadline(time_limit):
        return _compute(space, robot, slices, surfaces, no_limits, backend, timeout,
                        no_cache, progress)


def _compute(space: str, robot: str, slices, surfaces: str, no_limits: bool, backend: str,
             timeout: float, no_cache: bool, progress):
    from singcheck.api import elimination_engine, hard_time_limit
    from singcheck.budget import remaining
    from singcheck.elimination.projection import project_robot
    from singcheck.model.robot import build_model
    from singcheck.spaces.analysis import (
        LIMIT,
        WORKSPACE,
        analyse,
        check_free_axes,
        jointspace_variety,
        select_surfaces,
    )
    from singcheck.spec.files import load_robot

    fixed = _slices(slices)
    model = build_model(load_robot(robot))
    from singcheck.elimination.projection import refuse_elimination

    refuse_elimination(model, f"the discriminant variety of the {space} cannot be computed")
    engine = elimination_engine(backend, timeout, not no_cache, progress.note)
    axes = model.pose if space == WORKSPACE else model.joints
    check_free_axes(model, space, fixed)  # before the work, not after the projection
    with progress.status(f"computing the discriminant variety of the {space}"):
        if space == WORKSPACE:
            from singcheck.spaces.analysis import workspace_variety

            components = workspace_variety(project_robot(model, engine))
        else:
            components = jointspace_variety(model, engine)
    if no_limits:
        components = [c for c in components if c.kind != LIMIT]
    free = len([a for a in axes if a not in fixed])
    components, left_out = select_surfaces(components, space, surfaces, free)
    # the decomposition is pure Python: a timer backs up its checkpoints
    with progress.status(f"decomposing the {space} and counting solutions"), \
            hard_time_limit(remaining()):
        analysis = analyse(space, model, components, fixed, use_limits=not no_limits)
    progress.note(f"{len(analysis.cells)} cells in "
                  f"{sum(analysis.timings.values()):.2f} s")
    return analysis, left_out


def _command(space: str, robot, slices, surfaces, no_limits, backend, timeout, no_cache,
             time_limit, fmt, output, quiet, verbose) -> None:
    from singcheck.budget import TimeLimitExceeded
    from singcheck.cli.exitcodes import exit_codes

    progress = Progress(quiet)
    with exit_codes():
        from singcheck.report.spaces import analysis_json
        from singcheck.spaces.analysis import SliceError

        try:
            analysis, left_out = compute(space, robot, slices, surfaces, no_limits, backend,
                                         timeout, no_cache, progress, time_limit)
        except SliceError as e:
            raise click.BadParameter(str(e), param_hint="--slice") from None
        except TimeLimitExceeded as e:  # nothing partial is written
            click.echo(f"singcheck: unknown: {e} (the {space} analysis; --time-limit)",
                       err=True)
            sys.exit(int(ExitCode.UNKNOWN))
        unknown = any(c.count is None for c in analysis.cells if c.within_limits)
        code = ExitCode.UNKNOWN if unknown else ExitCode.SINGULARITY_FREE
        doc = analysis_json(analysis, left_out, int(code))
        text = _text(doc, fmt, verbose, bool(output))
        if output:
            from singcheck.atomic import write_output

            write_output(output, text)
        else:
            sys.stdout.write(text)
    sys.exit(int(code))


def _text(doc, fmt: str, verbose: bool, to_file: bool) -> str:
    from singcheck.report.spaces import render

    if fmt == "json":
        import json

        return json.dumps(doc, indent=2, ensure_ascii=False) + "\n"
    from singcheck.report.console import captured

    return captured(lambda console: render(console, doc, verbose),
                    interactive=sys.stdout.isatty() and not to_file, width=120)


_EXIT = """\b
Exit status:
  0  every cell's count is proven
  2  bad command line or bad spec file (an unknown axis, a slice inside a surface)
  3  some count could not be decided, or the analysis ran past --time-limit
  4  an elimination backend is missing or failed
"""


@click.command(epilog="""\b
Examples:
  singcheck workspace robots/orthoglide.yaml                 # 3-D cells and regions
  singcheck workspace robots/orthoglide.yaml --slice z=1     # the plane z = 1
  singcheck workspace robots/skew-biglide.yaml --format json
""" + _EXIT)
@_options("workspace")
def workspace(robot, slices, surfaces, no_limits, backend, timeout, no_cache, time_limit, fmt,
              output, quiet, verbose) -> None:
    """Where in the workspace the inverse kinematics has how many real solutions inside
    the joint limits, computed exactly.

    The discriminant variety (serial singularities, the parallel singularity surface
    ξ(X), the joint limits projected) cuts the pose space into open cells (a generic
    cylindrical algebraic decomposition with exact rational sample points); the number
    of solutions is counted exactly at each sample and holds on the whole cell.  Cells
    are joined into connected regions by exactly checked segments that avoid the
    variety; the output says whether the regions are proven to be exactly the
    connected components.
    """
    _command("workspace", robot, slices, surfaces, no_limits, backend, timeout, no_cache,
             time_limit, fmt, output, quiet, verbose)


@click.command(epilog="""\b
Examples:
  singcheck jointspace robots/orthoglide.yaml                  # 3-D cells and regions
  singcheck jointspace robots/orthoglide.yaml --slice rho3=2   # the plane rho3 = 2
""" + _EXIT)
@_options("jointspace")
def jointspace(robot, slices, surfaces, no_limits, backend, timeout, no_cache, time_limit, fmt,
               output, quiet, verbose) -> None:
    """Where in the joint space the direct kinematics has how many real solutions
    (assembly modes), computed exactly.

    The discriminant variety (the serial singularities projected, ε(ρ), the limit
    planes) cuts the joint space into open cells with exact rational samples; at each,
    the real poses are counted from a Gröbner basis in shape position.  Cells outside
    the joint-limit box are marked so.  Cells are joined into connected regions by
    exactly checked segments that avoid the variety.
    """
    _command("jointspace", robot, slices, surfaces, no_limits, backend, timeout, no_cache,
             time_limit, fmt, output, quiet, verbose)
