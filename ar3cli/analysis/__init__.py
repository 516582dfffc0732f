"""The robot-analysis layer: one robot loaded once, and every fact the front-ends show about it.

Three front-ends read the same facts about one robot: ``report`` (an HTML page), ``view`` (a live
3D viewer) and ``server`` (the editor's language server). They ask this layer, which sits below
``commands/`` and above the feature packages: it may import several features (a feature never
imports another), and it never parses options or writes output.

Load, then ask::

    from ar3cli.analysis.robot import RobotAnalysis
    from ar3cli.analysis.settings import AnalysisSettings
    from ar3cli.analysis.findings import static_findings

    analysis = RobotAnalysis.load(path, AnalysisSettings(packages=..., config=load_config()))
    answer = static_findings(analysis)          # computed once, then kept (thread-safe)
    analysis = RobotAnalysis.load(path, settings, text=buffer)   # an unsaved editor buffer

The questions, one module each (every question is ``function(analysis, *args)``):

- :mod:`~ar3cli.analysis.findings`: ``static_findings`` (lint-urdf) and ``findings`` (lint-urdf
  --sim), with the settings' configuration, ``--target`` and the file's suppressions;
- :mod:`~ar3cli.analysis.facts`: ``summary`` (info), ``torques`` (info --torques), ``home_pose``,
  and ``link_facts`` / ``joint_facts`` for one name (mass, parent and children, limits, axis);
- :mod:`~ar3cli.analysis.pictures`: ``pictures`` (three sides, visual and collision, contacts at home in red);
- :mod:`~ar3cli.analysis.collisions`: ``collision_matrix`` (sample-collisions);
- :mod:`~ar3cli.analysis.kinematics`: ``fk_verify``;
- :mod:`~ar3cli.analysis.cross_check`: ``cross_check`` (PyBullet against MuJoCo; None without the extra);
- :mod:`~ar3cli.analysis.verdict`: ``verdict``, one status built from every section's ``Check``
  (a check is ``@check(key, title)`` on a function returning an ``Outcome``; ``verdict(analysis,
  checks)`` takes any tuple of them, so a front-end adds its own without editing the module);
- :mod:`~ar3cli.analysis.report`: ``robot_report``, everything ``ar3cli report``'s page shows.

Adding a question is adding a module here (or a function in one), nothing else::

    from ar3cli.analysis.robot import RobotAnalysis, question

    @question
    def inertia_boxes(analysis: RobotAnalysis) -> list[Box]:
        model = analysis.require_model()      # UserError (the load's one line) when it did not load
        ...                                   # anything computed from model and analysis.settings

A question that needs pybullet runs it through :func:`ar3cli.sim.session.run_pybullet` (a forked
child) like every feature; one that keeps a child alive between calls (contacts at a viewer's
current pose) opens it with ``analysis.keep(key, open)``, and :meth:`RobotAnalysis.close`
(:mod:`~ar3cli.analysis.robot`) ends it. An answer depends only on the analysis and the
arguments: a new file content is a new analysis.

Reloading: ``analysis.changed()`` lists the files (the robot file unless a buffer stood in for it,
xacro includes, meshes, the places a missing mesh was looked for) whose state differs since the
load (:mod:`~ar3cli.analysis.dependencies`); ``analysis.reloaded()`` (or ``reloaded(text=...)``)
is the next snapshot. A load that fails gives an analysis without a model (``load_error`` says
why; the lint questions answer with its F finding) that still watches the last good load's files.
"""
