"""``python -m flatcontact``: the ``flatcontact`` command (:func:`flatcontact.cli.main`), for an
interpreter whose scripts folder is not on PATH or a source tree on PYTHONPATH."""

from flatcontact.cli import main

if __name__ == "__main__":
    main()
