"""The command-line interface: one thin module per command, chained by :mod:`.app`."""
