"""Import every command module so that its commands register on the app.

Add a line here when a new command module is written. The order of registration is the
order of ``flatcontact --help``.
"""

from flatcontact.cli import (  # noqa: F401  (imported for their @app.command registrations)
    analyze,
    build,
    contact,
    run,
    scan,
    train,
    validate,
)

# isort: split
from flatcontact.cli import (
    elastic,  # noqa: F401  (listed after validate-potential)
    study,  # noqa: F401  (study convergence|models, last)
    study_dilatancy,  # noqa: F401  (study dilatancy, registers on study's app)
)
