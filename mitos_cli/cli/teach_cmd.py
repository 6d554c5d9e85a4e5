"""``mitos teach``: the teaching prompt, a scripted lesson, or a resumed session."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from ..words import plural
from .params import WORDS, named

if TYPE_CHECKING:
    from collections.abc import Callable

    from ..lang.model import RuleBase
    from ..teach.session import Session


class Transcript:
    """What a lesson printed, command by command, for ``--json``."""

    def __init__(self) -> None:
        self.commands: list[dict] = []
        self.before: list[str] = []            # printed before the first command

    def command(self, echoed: str) -> None:
        """A lesson's echo ``path:line> text`` opens the next command's record."""
        where, _, text = echoed.partition("> ")
        line = where.rsplit(":", 1)[-1]
        self.commands.append({"line": int(line) if line.isdigit() else None,
                              "command": text if _ else echoed, "output": []})

    def out(self, text: str) -> None:
        target = self.commands[-1]["output"] if self.commands else self.before
        target.extend(str(text).splitlines())

    def to_json(self, session_dir: Path, session: Session) -> str:
        import json

        state = session.state
        return json.dumps({"session": session_dir.name,
                           "journal": (session_dir / "journal.jsonl").as_posix(),
                           "behavior": state.active, "examples": len(state.examples),
                           "unsaved": bool(session.unsaved), "commands": self.commands},
                          indent=2)


def teach_command(
    rules: Annotated[str | None, typer.Argument(
        click_type=WORDS, metavar="[RULEBASE]", callback=named,
        help="Rule file to teach (default: the packaged MITOS rule base).")] = None,
    behavior: Annotated[str | None, typer.Option(
        "--behavior", "-b", metavar="NAME", callback=named,
        help="The behavior to teach first (default: the file's first).")]
        = None,
    lesson: Annotated[str | None, typer.Option(
        "--lesson", "-l", metavar="FILE|NAME|-", callback=named,
        help="Run the commands of a lesson file, a packaged lesson by name (`mitos list "
             "lessons`) or stdin (-) instead of the prompt; stop at the first error "
             "(exit 1).")] = None,
    save_as: Annotated[str | None, typer.Option(
        "--save-as", "-o", metavar="OUT.rules", callback=named,
        help="Where `save` writes: OUT.rules and its term set beside it, OUT.terms.yaml (a "
             "rule file with several term sets, as the packaged one: OUT.<each term set's "
             "name>, e.g. OUT.mitos.terms.yaml and OUT.drive.terms.yaml); a lesson saves there "
             "when it ends. The original files are never overwritten unless you name them, "
             "nor a term set there that OUT.rules does not read.")] = None,
    resume: Annotated[bool, typer.Option(
        "--resume", help="Continue the last teaching session here (or --session NAME) from "
                         "its journal.")] = False,
    session_name: Annotated[str | None, typer.Option(
        "--session", metavar="NAME", callback=named, help="The session to resume (a name under "
                                          ".mitos/teach/).")] = None,
    recover: Annotated[bool, typer.Option(
        "--recover", help="With --resume: keep the changes before a damaged line of the "
                          "journal and continue from there (the damaged journal is kept as "
                          "journal.jsonl.damaged).")] = False,
    as_json: Annotated[bool, typer.Option(
        "--json", help="With --lesson: print one JSON object (each command and what it "
                       "printed; schema: `mitos docs teach`) instead of the transcript.")] = False,
) -> None:
    """Teach a rule base: tell rules and behaviors, correct outputs, adapt, save."""
    from .progress import stopped_code, terminate_as_interrupt

    _check_options(rules, behavior, lesson, save_as, resume, session_name, recover, as_json)
    # a SIGTERM or a SIGHUP stops the session as Ctrl-C does (it ended by the signal's
    # default, exit -15 or -1, without a word); the journal's writes hold all three
    with terminate_as_interrupt():
        try:
            _teach(rules, behavior, lesson, save_as, resume, session_name, recover, as_json)
        except KeyboardInterrupt as stop:       # (the words, where a session exists, said)
            raise typer.Exit(stopped_code(stop)) from None


def _teach(rules: str | None, behavior: str | None, lesson: str | None, save_as: str | None,
           resume: bool, session_name: str | None, recover: bool, as_json: bool) -> None:
    """The session opened or resumed, then its lesson run or its prompt read."""
    from ..teach.prompt import interact
    from .output import emit

    transcript = Transcript() if as_json else None
    out = transcript.out if transcript is not None else emit      # what the session prints
    if resume:
        session, lesson_text = _resumed(session_name, recover, save_as, out), None
    else:
        session, lesson_text = _new_session(rules, behavior, lesson, save_as, out)
    if lesson is not None:
        _teach_lesson(session, lesson, lesson_text, transcript)
        return
    interact(session, session.journal.directory / "history")


def _check_options(rules: str | None, behavior: str | None, lesson: str | None, save_as: str | None,
                  resume: bool, session_name: str | None, recover: bool,
                   as_json: bool) -> None:
    """The options that do not go together, before a session is opened or created."""
    from ..teach.save import nameless

    if recover and not resume:
        raise typer.BadParameter("--recover applies to a resumed session: add --resume")
    if save_as is not None and not save_as.endswith(".rules"):
        raise typer.BadParameter(f"--save-as names the rule file to write, ending in `.rules`, "
                                 f"not `{save_as}`")
    if save_as is not None and nameless(save_as):
        raise typer.BadParameter(f"--save-as names the rule file to write: `{save_as}` is only "
                                 f"the ending, give it a name (`--save-as "
                                 f"{Path(save_as).with_name('taught.rules').as_posix()}`)")
    if as_json and lesson is None:
        raise typer.BadParameter("--json reports a lesson: add --lesson FILE")
    if session_name is not None and not resume:
        raise typer.BadParameter("--session names a session to resume: add --resume")
    if resume and (rules is not None or behavior is not None):
        raise typer.BadParameter("--resume continues a session with its own rule file and "
                                 "behavior; give neither RULES nor --behavior")


def _resumed(session_name: str | None, recover: bool, save_as: str | None,
            out: Callable[[str], None]) -> Session:
    """The session ``--resume`` continues, replayed from its journal; what was found in the
    journal is said on stderr."""
    from ..errors import LessonError
    from ..teach.journal import Journal, find_session
    from ..teach.progress import epoch_progress
    from ..teach.session import Session
    from .output import err

    try:
        journal = Journal.open(find_session(session_name), recover=recover)
        session = Session.resume(journal, out=out, progress=epoch_progress, recover=recover)
    except LessonError as exc:          # the session, not a lesson, is what is wrong
        exc.kind = "session error"
        raise
    if save_as is not None:
        _check_save_as(session.original, save_as)
        session.save_as = Path(save_as)
    err(f"resumed session {journal.directory.name}: {plural(len(journal.active()), 'change')}, "
        f"{plural(len(session.state.examples), 'example')}, behavior {session.state.active}"
        + (f"; the last change was incomplete (the journal was cut short during a write) "
           f"and was dropped; the journal as it was is kept as {journal.aside}"
           if journal.skipped_tail else "")
        + (f"; recovered up to the damaged line {journal.recovered_at} of the journal "
           f"(kept as {journal.aside})" if journal.recovered_at else "")
        + (f"; behavior `{session.state.block}` is still open (`end` closes it)"
           if session.state.block is not None else ""))
    return session


def _new_session(rules: str | None, behavior: str | None, lesson: str | None, save_as: str | None,
                out: Callable[[str], None]) -> tuple[Session, tuple[str, str] | None]:
    """A new session on ``rules`` (a path, or a packaged rule base's name, as ``eval`` and
    ``check`` take it) and the lesson's text, read first: a bad rule file, behavior or
    lesson is refused before a session exists (an empty session would be the newest, the one
    ``mitos teach --resume`` picks)."""
    from ..api import default_rulebase_path, load_rulebase
    from ..errors import MitosError, RuleBaseError
    from ..resources import resolve
    from ..teach.journal import Journal, new_session_dir
    from ..teach.lesson import read_lesson
    from ..teach.progress import epoch_progress
    from ..teach.session import Session
    from .output import err

    path = Path(rules) if rules is not None else default_rulebase_path()
    try:                # in a directory this user cannot enter: a PermissionError traceback
        if rules is not None and not path.exists():
            path = resolve("rulebases", rules, ".rules") or path
        is_file = path.is_file()
    except OSError as exc:
        raise RuleBaseError(f"cannot read rule file `{path}`: {exc.strerror or exc}") from None
    if not is_file:
        from ..fileio import broken_link
        from ..lang.resolve import rule_file_not_found_hint

        link = broken_link("rule file", path)       # a dangling link, a loop: as eval says it
        raise RuleBaseError(link or (f"`{path}` is a directory, not a rule file" if path.is_dir()
                                     else f"rule file `{path}` not found"),
                            hint=None if path.is_dir() or link else
                            (rules and _a_lesson(rules)) or rule_file_not_found_hint(path))
    try:
        loaded = load_rulebase(path, behavior)
    except MitosError as exc:           # a .fis, .fcl or .fll (by its name or not): convert it
        from ..interop import hint_wrong_reader

        hint_wrong_reader(exc, path, "mitos teach")
        if path.suffix.lower() in (".yaml", ".yml") and exc.span is None:
            # the loader's hint named .fcl, .fis and .fll rule bases, which teach refuses
            exc.hint = ("`mitos teach` teaches a .rules file (convert a .fcl, .fis or .fll one "
                        "with `mitos convert FILE --to rules`); a term set is read through the "
                        "`terms` line of its .rules file, and a world is driven from the "
                        "prompt (`simulate WORLD`)")
        raise
    if save_as is not None:         # refused now, not when the lesson ends and saves
        _check_save_as(loaded.rulebase, save_as)
    lesson_text = read_lesson(lesson) if lesson is not None else None
    journal = Journal.create(new_session_dir(path.stem))
    session = Session(path, behavior, journal, save_as, out=out, progress=epoch_progress)
    err(f"session {journal.directory.name} (journal in {journal.directory.as_posix()}; "
        f"`mitos teach --resume` continues it)")
    return session, lesson_text


def _a_lesson(given: str) -> str | None:
    """Where a lesson goes, for one named where the rule base goes that is not there: a
    packaged lesson by the name `--lesson` takes (`mitos teach wider-turn`), or a `.lesson`
    file (it said "rule file not found", and `mitos list` shows the packaged rule bases)."""
    from ..resources import resolve

    packaged = resolve("rulebases/lessons", given, ".lesson") is not None
    if not packaged and not given.lower().endswith(".lesson"):
        return None
    return (f"`{given}` is {'a packaged lesson' if packaged else 'a lesson'}, not a rule base: "
            f"a lesson is run with --lesson (`mitos teach [RULEBASE] --lesson {given}`)")


def _check_save_as(rulebase: RuleBase, save_as: str) -> None:
    """Refuse ``--save-as`` where a save cannot be made (a read-only directory, a term set there
    that is not its own, ...) before a session starts, not once the lesson has run."""
    from ..errors import LessonError
    from ..teach.save import check_save_target

    try:
        check_save_target(rulebase, Path(save_as))
    except LessonError as exc:
        exc.hint = exc.hint or (f"give --save-as a place you can write (`--save-as "
                                f"~/{Path(save_as).name}`)")
        raise


def _ended_open(session: Session, text: str, name: str) -> None:
    """A lesson that ends with a behavior still open, told at the line that opened it (or at
    the lesson's end, when it was open before): a warning, since the session keeps it open
    for ``--resume`` to close; with ``--save-as`` an error, since the save asked for cannot be
    made (a behavior half told is not saved)."""
    from ..errors import LessonError
    from ..teach.lesson import lesson_end
    from .output import err

    where = session.opened_at or lesson_end(text, name)
    from ..teach.journal import resume_command

    resume = resume_command(session.journal.directory)
    if session.save_as is not None:
        raise LessonError(f"the lesson ended with behavior `{session.state.block}` still open, "
                          f"so it cannot be saved to {session.save_as}", span=where,
                          hint=f"close it with `end` in the lesson, or continue the session "
                               f"(`{resume}`): every change is in its journal")
    err(f"{where}: warning: the lesson ended with behavior `{session.state.block}` still open; "
        f"`end` closes it (`{resume}`)")


def _teach_lesson(session: Session, lesson: str, lesson_text: tuple[str, str] | None,
                  transcript: Transcript | None) -> None:
    """Run a lesson file (or stdin) in ``session``; save where ``--save-as`` says if it ends
    with changes unsaved. Ctrl-C, a SIGTERM or a SIGHUP keeps every change (the journal has
    them) and exits 130, 143 or 129."""
    from ..resources import packaged_name
    from ..teach.journal import resume_command
    from ..teach.lesson import read_lesson
    from .output import emit, err
    from .progress import stopped_code

    text, found = lesson_text if lesson_text is not None else read_lesson(lesson)
    directory = session.journal.directory
    session.echo = transcript.command if transcript is not None else emit
    if lesson != "-":
        session.base = Path(found).parent
    # a packaged lesson (`--lesson wider-turn`) is shown by its name in the repository, as the
    # packaged rule base is, not by the path pip put it at
    name = packaged_name(found) or found if lesson != "-" else found
    try:
        _run_and_save(session, text, name, transcript)
    except KeyboardInterrupt as stop:    # in the save at the end too (it exited 130 unsaid)
        err(f"interrupted: every change so far is in the journal; "
            f"`{resume_command(directory)}` continues")
        raise typer.Exit(stopped_code(stop)) from None
    if transcript is not None:
        emit(transcript.to_json(directory, session))


def _run_and_save(session: Session, text: str, name: str, transcript: Transcript | None) -> None:
    """The lesson's commands, then the save ``--save-as`` asks for."""
    from ..errors import MitosError
    from ..teach.lesson import run_lesson
    from .output import err

    directory = session.journal.directory
    try:
        run_lesson(session, text, name)
    except MitosError:
        if session.journal.discard_if_unused():
            err(f"session {directory.name} removed: the lesson stopped before any change")
        raise
    if session.state.block is not None:
        _ended_open(session, text, name)
    if session.save_as is not None and session.unsaved:
        if transcript is not None:
            transcript.command("save (the lesson ended with unsaved changes)")
        try:
            session.run("save")
        except MitosError as exc:   # no prompt to `save ~/...` at: how to go on
            if exc.message.startswith(("cannot save", "cannot create")):
                from ..teach.journal import resume_command

                exc.hint = (f"every change is in the session's journal: "
                            f"`{resume_command(directory)}`, then `save PATH` where you can "
                            f"write")
            raise
