"""Dataset scans: check every robot file under some folders, one row per file in a SQLite store.

A scan is resumable (a file whose content hash and settings are stored is not checked again),
writes rows as results arrive, contains crashes and slow files per file, and can spread the work
over a Ray cluster. The per-file check itself (the linter) is handed in by the command layer as a
function (:data:`~ar3cli.scan.worker.LintFunction`): features stay independent of each other, and
this package knows rows, not rules.
"""
