"""Import every command module so that its commands register on the app.

Add a line here when a new command module is written.
"""

from flatcontact.cli import (  # noqa: F401  (imported for their @app.command registrations)
    analyze,
    build,
    contact,
    elastic,
    run,
    scan,
    train,
    validate,
)
