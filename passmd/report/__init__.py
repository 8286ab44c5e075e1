"""The book and the command line's presentation: the figure table, the ledger's views,
the chapters' helpers and the table of assumptions."""
