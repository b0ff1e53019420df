"""``python -m flatcontact`` and the ``flatcontact`` console script: :func:`main`.

:func:`main` installs the start-up SIGTERM handler
(:func:`flatcontact.foundation.interrupts.exit_on_sigterm`) before anything heavy is imported,
then imports the command line (typer, rich, numpy and the settings: most of a second) and
runs :func:`flatcontact.cli.main`. A SIGTERM at any moment after :func:`main` starts thus
ends the command with the one ``error: terminated (SIGTERM)`` line and status 143, and a
Ctrl-C with the one ``error: interrupted`` line and status 130 (before, either came as a
silent -15 or a ``KeyboardInterrupt`` traceback while the command line was being imported);
only the interpreter's own start-up and the import of this module (the light ``flatcontact``
package, ``python -m benchmarks startup``) come before it.
"""

import sys

from flatcontact.foundation.interrupts import INTERRUPTED_LINE, INTERRUPTED_STATUS, exit_on_sigterm


def main() -> None:
    """Entry point of the ``flatcontact`` command (pyproject's ``[project.scripts]``)."""
    exit_on_sigterm()
    try:
        from flatcontact.cli import main as cli_main

        cli_main()
    except KeyboardInterrupt:  # Ctrl-C before the command line handles it (in its imports)
        sys.stderr.write(f"error: {INTERRUPTED_LINE}\n")
        sys.exit(INTERRUPTED_STATUS)


if __name__ == "__main__":
    main()
