"""``mitos convert``: a rule base in another format (MITOS rules, FCL, FIS, FLL)."""

from __future__ import annotations

from enum import Enum
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Optional

import typer

from .output import emit, err, warn, warn_notes
from .params import FILE, choice, choices, completer, file_arg, named, target_of
from .targets import check_suffix, refuse_existing, refuse_inputs, refuse_strays, source_files

if TYPE_CHECKING:
    from ..lang.model import RuleBase


class Target(str, Enum):
    rules = "rules"
    fcl = "fcl"
    fis = "fis"
    fll = "fll"


class Dialect(str, Enum):
    """Which FCL readers the written FCL is for (``mitos_cli.interop.fcl.DIALECTS``)."""

    fuzzylite = "fuzzylite"    # fuzzylite 6: ACCU in DEFUZZIFY, `and` between conclusions
    iec = "iec"                # IEC 61131-7, jFuzzyLogic: ACCU in the RULEBLOCK, `,`


def convert_command(
    path: Annotated[Optional[Path], typer.Argument(
        click_type=FILE, metavar="[FILE]", help="Rule base to convert (.rules, .fcl, .fis or .fll; "
                                                "default: the packaged MITOS rule base).")] = None,
    to_name: Annotated[Optional[str], typer.Option(
        "--to", metavar=choices(Target), autocompletion=completer(Target),
        help="Format to write: rules (NAME.rules + NAME.terms.yaml), fcl, fis or fll "
             "(default: the one -o's extension names).")] = None,
    output: Annotated[Optional[Path], typer.Option(
        "--output", "-o", parser=file_arg, metavar="OUT",
        help="File to write, ending in the format's extension (default: stdout; for --to "
             "rules: STEM.rules and STEM.terms.yaml in the current directory, never over "
             "existing files). -o OUT.rules also writes OUT.terms.yaml, never over a file "
             "there that OUT.rules does not read.")] = None,
    behavior: Annotated[Optional[str], typer.Option(
        "--behavior", "-b", metavar="NAME", callback=named,
        help="Behavior to convert (default: the file's first).")] = None,
    dialect_name: Annotated[Optional[str], typer.Option(
        "--dialect", metavar=choices(Dialect), autocompletion=completer(Dialect),
        help="With --to fcl, the readers to write for: fuzzylite (fuzzylite 6, the default) "
             "or iec (IEC 61131-7 and jFuzzyLogic). They differ in where ACCU stands and "
             "what joins two conclusions (`mitos docs interop`).")] = None,
) -> None:
    """Convert a rule base between the MITOS rule language, FCL, MATLAB .fis and fuzzylite FLL.

    Reading back what was written gives the same outputs; what the target format cannot say
    is refused with the reason.
    """
    from ..api import default_rulebase_path, read_rulebase
    from ..interop import conversion_notes, parse_foreign, round_trip_difference, write_foreign
    from ..interop.common import atomic_write

    to = target_of(Target, to_name, output, {t: f".{t.value}" for t in Target}, "format")
    dialect = None if dialect_name is None else choice(Dialect, dialect_name, "FCL dialect")
    if dialect is not None and to is not Target.fcl:
        raise typer.BadParameter(f"--dialect chooses between FCL's dialects; --to {to.value} "
                                 f"has none (leave --dialect out)")
    if output is not None:
        check_suffix(output, f".{to.value}", f"--to {to.value}")
    path = path if path is not None else default_rulebase_path()
    rb = read_rulebase(path)
    warn_notes(rb)
    if behavior is not None:
        rb.behavior(behavior)                     # unknown behavior: did you mean
    sources = source_files(rb, path)
    if to is Target.rules:
        from ..interop.rules_writer import write_rules

        rules_path = output if output is not None else Path(f"{path.stem}.rules")   # (here)
        terms_path = rules_path.with_name(rules_path.stem + ".terms.yaml")
        _refuse_undecodable(terms_path, output is None)
        refuse_inputs([rules_path, terms_path], sources)
        refuse_strays(rules_path, [terms_path])       # a term set no rule file here reads
        if output is None:
            refuse_existing([rules_path, terms_path], rules_path.name)
        rules_text, terms_text = write_rules(rb, terms_path.name, behavior, _text(path.name))
        for note in conversion_notes(rb, "rules", behavior):
            warn(note)
        back = _read_back(rules_text, terms_text, rules_path, terms_path)
        _write_pair(rules_path, rules_text, terms_path, terms_text)
        for note in round_trip_difference(rb, back, "rules", behavior):
            warn(note)
        err(f"wrote {rules_path} and {terms_path}")
        return
    if output is not None:
        refuse_inputs([output], sources)
    text = write_foreign(rb, to.value, behavior, None if dialect is None else dialect.value)
    for note in conversion_notes(rb, to.value, behavior):
        warn(note)
    for note in round_trip_difference(rb, parse_foreign(text, to.value, str(output or "-")),
                                      to.value, behavior):
        warn(note)
    if output is None:
        emit(text)
    else:
        atomic_write(output, text)
        err(f"wrote {output}")


def _text(name: str) -> str:
    """A file name as text: a byte that is not UTF-8 (Python's lone surrogate) as U+FFFD."""
    return name.encode("utf-8", "surrogateescape").decode("utf-8", "replace")


def _refuse_undecodable(terms_path: Path, derived: bool) -> None:
    """The term set's name goes into the rule file's `terms` line, which is UTF-8 text: a name
    that is not (a source file named in another encoding) was refused inside MITOS's own
    output, as "a defect of `mitos convert`"."""
    if _text(terms_path.name) == terms_path.name:
        return
    shown = terms_path.name.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")
    raise typer.BadParameter(
        f"the term set's name `{shown}` is not UTF-8 text, which the rule file's `terms` line "
        f"is: {'name the output with -o OUT.rules' if derived else 'choose another name'}",
        param_hint="'-o' / '--output'")


def _write_pair(rules_path: Path, rules_text: str, terms_path: Path, terms_text: str) -> None:
    """The rule file and its term set as one set, as `teach` saves them: written one after
    the other, a kill between them, or a rule file that could not be written (a directory
    of its name), left a new term set beside the old rule file, or beside none."""
    from ..fileio import atomic_write_set, check_writable

    check_writable(terms_path)
    check_writable(rules_path)
    atomic_write_set([(terms_path, terms_text), (rules_path, rules_text)], rules_path)


def _read_back(rules_text: str, terms_text: str, rules_path: Path, terms_path: Path) -> RuleBase:
    """The rule base the two files will hold, read before they are written: a conversion
    no command could read is refused with nothing written (it used to be written, then
    refused inside MITOS's own output)."""
    from ..errors import MitosError
    from ..lang.parse import parse_rules
    from ..lang.resolve import build_rulebase
    from ..lang.termfile import parse_termset

    try:
        parsed = parse_rules(rules_text, str(rules_path))
        return build_rulebase(parsed, (parse_termset(terms_text, str(terms_path)),),
                              (terms_path.name,))
    except MitosError as exc:
        exc.hint = ("nothing was written: this is what the conversion would have written, "
                    "which MITOS cannot read back (a defect of `mitos convert`; please report "
                    "it with the source file)")
        raise
