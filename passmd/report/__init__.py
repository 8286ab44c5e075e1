"""The book and the command line's presentation: the ledger's evaluation over every chapter's
results and its views, the chapters' helpers and the table of assumptions."""
