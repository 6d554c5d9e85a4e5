"""``python -m mitos_cli`` and the ``mitos`` script (:func:`run`)."""

import sys


def run() -> None:
    """The command line; a Ctrl-C while its modules load (about 0.1 s) exits 130, as one
    during a command does, instead of printing the traceback of an import."""
    try:
        from .cli.app import main
    except KeyboardInterrupt:
        sys.exit(130)
    main()


if __name__ == "__main__":
    run()
