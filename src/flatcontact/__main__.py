"""``python -m flatcontact`` and the ``flatcontact`` console script: :func:`main`.

:func:`main` installs the start-up SIGTERM handler
(:func:`flatcontact.foundation.interrupts.exit_on_sigterm`) before anything heavy is imported,
then imports the command line (typer, rich, numpy and the settings: most of a second) and
runs :func:`flatcontact.cli.main`. A SIGTERM at any moment after :func:`main` starts thus
ends the command with the one ``error: terminated (SIGTERM)`` line and status 143; only the
interpreter's own start-up and the import of this module (the light ``flatcontact`` package)
come before it.
"""

from flatcontact.foundation.interrupts import exit_on_sigterm


def main() -> None:
    """Entry point of the ``flatcontact`` command (pyproject's ``[project.scripts]``)."""
    exit_on_sigterm()
    from flatcontact.cli import main as cli_main

    cli_main()


if __name__ == "__main__":
    main()
