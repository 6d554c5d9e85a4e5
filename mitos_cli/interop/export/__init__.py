"""Code export: a compiled behavior as one self-contained C99 file or one NumPy-only module.

Both backends (:mod:`.c`, :mod:`.python`) write the same straight-line program
(:mod:`.program`): one membership per input term, one expression per rule, then the output
layer. The arithmetic is MITOS's own (the same compiled kernel for piecewise-linear terms, the
same norm formulas, Mamdani consequent sets sampled by :mod:`mitos_cli.engine.mamdani` and stored as
tables), so the generated code agrees with ``mitos eval`` to rounding (the tests check 1e-9).

Nothing read from a file is spliced into the code: names become checked identifiers
(``[A-Za-z0-9_]``, made unique) or escaped text in comments, docstrings and literals.
"""

from .c import comment, to_c
from .program import Program, ident, num, program
from .python import doc_text, to_python

__all__ = ["Program", "comment", "doc_text", "ident", "num", "program", "to_c", "to_python"]
