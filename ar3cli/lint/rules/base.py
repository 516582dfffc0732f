"""The pieces every lint rule is made of: :class:`Rule`, :class:`Hit` and the :func:`rule` decorator.

A rule is a generator function ``check(ctx) -> Iterator[Hit]`` plus its metadata (stable code,
severity, title, documentation with a failing and a passing example). Rules never build
:class:`~ar3cli.findings.Finding` objects themselves: they yield a :class:`Hit` naming the
element at fault, and the engine (:mod:`ar3cli.lint.engine`) turns it into a Finding with path, line,
column, suppression and configured severity. That keeps each rule a few lines of logic.
"""

from __future__ import annotations

import textwrap
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ar3cli.findings import Severity

if TYPE_CHECKING:
    from ar3cli.lint.context import Context

FAMILIES = {
    "F": "file",
    "S": "structure",
    "J": "joints",
    "I": "inertia",
    "G": "geometry",
    "P": "pybullet",
    "M": "mujoco",
    "T": "targets",
}
"""Code prefix -> family name; the prefix is the first letter of every code. Its order is the family
order of the registry, docs/rules.md and every listing (:data:`FAMILY_ORDER`)."""
FAMILY_ORDER = "".join(FAMILIES)
"""The family prefixes in registry order: ``"FSJIGPMT"``."""

ENGINES = ("pybullet", "ros", "mujoco", "isaac", "drake", "gazebo")
"""The engines and tools a rule can be about, by the names ``lint-urdf --target`` takes: ``ros`` stands
for urdfdom and everything built on it (check_urdf, robot_state_publisher, RViz, MoveIt, KDL)."""
EVERY_ENGINE = "any"
"""A rule about the file's meaning in every consumer (a typed degree, a missing mesh): never target-bound."""
ENGINE_NAMES = {"pybullet": "PyBullet", "ros": "ROS (urdfdom)", "mujoco": "MuJoCo", "isaac": "Isaac Sim",
                "drake": "Drake", "gazebo": "Gazebo", EVERY_ENGINE: "every engine"}
"""How docs/rules.md names each engine."""


@dataclass(frozen=True)
class Hit:
    """One problem as a rule reports it: a message about ``element`` (an lxml element) or ``line``.

    ``hint`` replaces the rule's default hint when the fix depends on the case.
    """

    message: str
    element: Any = None
    line: int = 0
    hint: str | None = None


Check = Callable[["Context"], Iterator[Hit]]


@dataclass(frozen=True)
class Rule:
    """A lint rule: metadata for docs/config/SARIF plus the ``check`` generator.

    ``bad`` and ``good`` are complete small URDF documents: the docs show them and the tests lint
    them (``bad`` must trigger the rule, ``good`` must not), so the documentation cannot drift.
    ``check`` is None for file rules the engine emits itself while loading.

    Optional documentation, shown in docs/rules.md (and available to SARIF and other renderers):
    ``fixed_by`` names the ar3cli command that fixes the finding (with the option it needs, if
    any), ``thresholds`` the constants the rule compares against and their values, and
    ``references`` the spec text or engine source the rule follows. ``opt_in`` rules run only
    when their code is named in ``select`` (``--select G013``, not ``ALL`` or a prefix): they read
    every collision mesh's triangles, which a cold lint of a large robot cannot afford by default.
    """

    code: str
    name: str
    severity: Severity
    title: str
    why: str
    fix: str
    bad: str
    good: str
    check: Check | None = None
    needs_sim: bool = False
    fixed_by: str | None = None
    thresholds: str | None = None
    references: str | None = None
    opt_in: bool = False
    targets: tuple[str, ...] = ()
    """The engines (``lint-urdf --target``) whose traps this rule reports; empty for every engine."""
    engines: tuple[str, ...] = (EVERY_ENGINE,)
    """What the finding is about: the engines and tools (:data:`ENGINES`) in which its consequence
    happens, or :data:`EVERY_ENGINE`. A rule that names engines only is target-bound: when
    ``--target`` names none of them its findings are infos (:meth:`severity_for`)."""
    breaks: str | None = None
    """For an error: which engine or tool refuses the file or measurably misbehaves on it, and how (the
    severity policy of docs/rules.md; ``tests/test_severity_policy.py`` holds every error rule to it)."""
    refused_by: tuple[str, ...] = ()
    """The engines (:data:`ENGINES`) that refuse to load a file with this finding: P001 and M001, which
    load it, stay quiet about a refusal a static rule already explains."""

    @property
    def family(self) -> str:
        return FAMILIES[self.code[0]]

    @property
    def target_bound(self) -> bool:
        """True when the finding matters only to the engines the rule names (not every engine), so
        its severity follows ``--target``. Simulation rules are about the engine ``--engine`` chose, T
        rules run only for their targets (or when their code is named, which chooses the engine)."""
        return EVERY_ENGINE not in self.engines and not self.needs_sim and not self.targets

    def severity_for(self, targets) -> Severity:
        """The severity of this rule's findings for a robot meant for ``targets``: the declared one,
        or info for a target-bound rule none of whose engines is a target (PyBullet's 1 kg default,
        I002, is noise to a ROS-only robot)."""
        if self.target_bound and not set(self.engines) & set(targets):
            return Severity.INFO
        return self.severity

    @property
    def anchor(self) -> str:
        """The heading anchor of this rule in docs/rules.md."""
        return f"{self.code.lower()}-{self.name}"


_REGISTERED: dict[str, Rule] = {}
"""Every rule made by :func:`rule`, by code: defining a rule registers it (see :func:`registered`)."""


def _register(made: Rule) -> Rule:
    """Add ``made`` to the registry; a second rule with the same code is a programming error."""
    if made.code[:1] not in FAMILIES or len(made.code) != 4:
        raise ValueError(f"rule code {made.code!r} must be a family prefix ({FAMILY_ORDER}) and three digits")
    known = _REGISTERED.get(made.code)
    if known is not None and known.name != made.name:
        raise ValueError(f"duplicate rule code {made.code}: {known.name} and {made.name}")
    _REGISTERED[made.code] = made
    return made


def registered() -> tuple[Rule, ...]:
    """Every rule defined so far, in family order then by code. ``ar3cli.lint.rules`` imports every
    module of its package first, so from there this is every rule there is."""
    return tuple(sorted(_REGISTERED.values(), key=lambda r: (FAMILY_ORDER.index(r.code[0]), r.code)))


def rule(code: str, name: str, severity: str, title: str, *, why: str, fix: str, bad: str, good: str,
         needs_sim: bool = False, fixed_by: str | None = None, thresholds: str | None = None,
         references: str | None = None, opt_in: bool = False,
         targets: tuple[str, ...] = (), engines: tuple[str, ...] | None = None, breaks: str | None = None,
         refused_by: tuple[str, ...] = ()) -> Callable[[Check | None], Rule]:
    """Decorator turning a check function into a :class:`Rule` and registering it: a rule written
    anywhere in the ``ar3cli.lint.rules`` package is in the engine, the docs and the tests (the
    function's name is unused). ``engines`` defaults to the rule's ``targets`` (a T rule is about its
    engines), else to every engine."""

    def wrap(check: Check | None) -> Rule:
        return _register(Rule(code=code, name=name, severity=Severity(severity), title=title,
                              why=" ".join(why.split()), fix=" ".join(fix.split()),
                              bad=dedent(bad).strip() + "\n", good=dedent(good).strip() + "\n",
                              check=check, needs_sim=needs_sim, fixed_by=fixed_by,
                              thresholds=" ".join(thresholds.split()) if thresholds else None,
                              references=" ".join(references.split()) if references else None, opt_in=opt_in,
                              targets=targets, engines=engines or targets or (EVERY_ENGINE,),
                              breaks=" ".join(breaks.split()) if breaks else None, refused_by=refused_by))

    return wrap


def dedent(text: str) -> str:
    """:func:`textwrap.dedent`, without its regular expressions for text indented with spaces only.

    Every rule's examples are dedented when its module is imported (350 calls, ~3 ms of each run's
    start-up with textwrap's regexes). Blank lines become empty and the common indent of the other
    lines is removed, as textwrap does; text holding a tab or another character textwrap's patterns
    treat specially (a carriage return) goes to textwrap itself.
    """
    if "\t" in text or "\r" in text:
        return textwrap.dedent(text)
    lines = [line if line.strip(" ") else "" for line in text.split("\n")]
    margin = min((len(line) - len(line.lstrip(" ")) for line in lines if line), default=0)
    if margin:
        lines = [line[margin:] for line in lines]
    return "\n".join(lines)


def refusal_explained(ctx, engine: str) -> str | None:
    """The code of a static rule that fires on this file and says ``engine`` refuses it (its
    ``refused_by``), or None: P001 and M001, which load the file, then add nothing to the static
    finding that already names the cause at its line (one cause, one finding)."""
    for rule in registered():  # every rule: the package imported all its modules before any rule runs
        if engine in rule.refused_by and not rule.needs_sim and rule.check is not None:
            for _hit in rule.check(ctx):
                return rule.code
    return None


def error_explained(ctx, element) -> str | None:
    """The code of a static rule that reports an error at ``element`` or inside it (for this file's targets),
    or None: an engine's refusal that names the link a static error is about (MuJoCo's "mjMINVAL (link
    'odom_tx')" where I001 says the link has no <inertial>) adds nothing to it. Once per file."""
    from ar3cli.findings import Severity

    if element is None:
        return None
    def build(_model) -> dict:
        found: dict = {}
        for rule in registered():
            if rule.check is None or rule.needs_sim or rule.severity_for(ctx.targets) is not Severity.ERROR:
                continue
            for hit in rule.check(ctx):
                if hit.element is not None:
                    found.setdefault(hit.element, rule.code)
        return found
    reported = ctx.shared("error-elements", build)
    for node in element.iter():
        if node in reported:
            return reported[node]
    return None


def elements_reported(ctx, codes: tuple[str, ...]) -> set:
    """The elements the static rules ``codes`` report in this file (once per file and list): an engine rule
    whose finding would restate one of them at the same element leaves it to the static rule."""
    def build(_model) -> set:
        found = set()
        for rule in registered():
            if rule.code in codes and rule.check is not None and not rule.needs_sim:
                found.update(hit.element for hit in rule.check(ctx) if hit.element is not None)
        return found
    return ctx.shared("reported:" + ",".join(codes), build)


def engine_rule(code: str, name: str, severity: str, title: str, **docs: str) -> Rule:
    """A rule whose findings the engine produces (load failures), with no check of its own."""
    return rule(code, name, severity, title, **docs)(None)


def robot(body: str, name: str = "r") -> str:
    """Wrap URDF elements in a ``<robot>`` document (for the doc examples)."""
    inner = textwrap.indent(dedent(body).strip(), "  ")
    return f'<?xml version="1.0"?>\n<robot name="{name}">\n{inner}\n</robot>\n'


LINK_INERTIAL = '<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'
"""A valid inertial for a 1 kg, ~0.25 m body, used by doc examples."""


def arm(joint_extra: str = '<limit lower="-1" upper="1" effort="10" velocity="1"/>',
        joint_type: str = "revolute", link_extra: str = LINK_INERTIAL,
        base_extra: str = "", joint_attrs: str = "") -> str:
    """A two-link robot with one joint, parameterised for the doc examples."""
    return robot(f"""
        <link name="base">{base_extra}</link>
        <link name="arm">{link_extra}</link>
        <joint name="j1" type="{joint_type}"{joint_attrs}>
          <parent link="base"/><child link="arm"/>
          <axis xyz="0 0 1"/>
          {joint_extra}
        </joint>
        """)
