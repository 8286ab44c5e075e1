"""The replication ledger: the paper's claims (schema, loader), the numeric checks, the
assumption space (readings), the closed-form reference curves, the verdict of one claim
and the evaluation of all of them against our computed results."""
