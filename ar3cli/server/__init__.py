"""``ar3cli server``: the language server, ar3cli's linter inside the editor (LSP over stdio).

A front-end of the robot-analysis layer (:mod:`ar3cli.analysis`), like ``report``: each open
``.urdf`` / ``.xacro`` buffer is a :class:`~ar3cli.analysis.robot.RobotAnalysis`, checked with
lint-urdf's rules and configuration as it is typed, and the facts hover and the outline show are
that layer's questions. The modules, one job each:

- :mod:`~ar3cli.server.launch`: start it (the optional ``server`` extra, pygls and lsprotocol, is
  imported there, and a missing one is one line naming the pip command);
- :mod:`~ar3cli.server.protocol`: the pygls handlers, the debounce and the worker threads;
- :mod:`~ar3cli.server.options`: the command line's options and the editor's settings;
- :mod:`~ar3cli.server.checks`: one check of one buffer version, findings to diagnostics per file;
- :mod:`~ar3cli.server.documents`: the open files, their checks, who includes whom, bounded memory;
- :mod:`~ar3cli.server.diagnostics`, :mod:`~ar3cli.server.ranges`: a finding as a diagnostic, and
  the range it underlines;
- :mod:`~ar3cli.server.cursor`: what the cursor is on, read forgivingly from the buffer;
- :mod:`~ar3cli.server.hover`, :mod:`~ar3cli.server.actions`, :mod:`~ar3cli.server.navigation`,
  :mod:`~ar3cli.server.completion`: the features.

Only :mod:`~ar3cli.server.options` and :mod:`~ar3cli.server.launch` may be imported without the extra.
"""
