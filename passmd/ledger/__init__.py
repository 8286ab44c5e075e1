"""The replication ledger's machinery: the paper's claims (schema, loader), the numeric checks
and the tags chapters put on their claim extractors, the assumption space (readings), the
closed-form reference curves, the joint reading and the verdict of one claim.
:mod:`passmd.report.evaluation` evaluates all of them against the chapters' results."""
