"""``ar3cli view``: a live 3D viewer of one robot file, on viser (the optional extra ``ar3cli[view]``).

A front-end of the robot-analysis layer (:mod:`ar3cli.analysis`), like ``report`` and ``server``: it
asks that layer for the geometry (``meshes``), the equivalent inertia boxes (``inertia_boxes``), the
joint controls and link frames at a pose (``poses``), the findings on each link (``findings``,
``link_findings``) and the pairs in contact at the current pose (``contacts``, in a pybullet child
kept alive while the sliders move), and it reloads when ``RobotAnalysis.changed()`` says a file
changed. This package only draws and listens:

- :mod:`~ar3cli.view.scene`: one load as viser scene nodes (moved, recoloured, shown or hidden);
- :mod:`~ar3cli.view.panel`: the control panel (status, check boxes, sliders, findings, the clicked link);
- :mod:`~ar3cli.view.describe`: the panel's texts, and :mod:`~ar3cli.view.text` their escaping;
- :mod:`~ar3cli.view.viewer`: what is on screen, the reload, the contact worker;
- :mod:`~ar3cli.view.server`: the viser server, the address checks, the poll loop and the stop.

viser is imported only inside these modules' functions: ``ar3cli --help`` and every other command
work without it, and ``ar3cli view`` without it says the pip command that installs it.
"""
