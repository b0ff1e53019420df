"""Import every command module so that its commands register on the app.

Add a line here when a new command module is written.
"""

import importlib

_COMMAND_MODULES = [
    "flatcontact.cli.contact",
    "flatcontact.cli.analyze",
    "flatcontact.cli.build",
    "flatcontact.cli.scan",
    "flatcontact.cli.training",
    "flatcontact.cli.run",
]

for _name in _COMMAND_MODULES:
    try:
        importlib.import_module(_name)
    except ModuleNotFoundError as _exc:  # a command module not written yet
        if _exc.name != _name:
            raise
