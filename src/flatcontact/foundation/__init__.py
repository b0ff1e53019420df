"""The foundation layer: what every other layer stands on (docs/architecture.md, layer 1).

``layout`` (run-directory folder and file names), ``reference`` (the paper's and literature
values), ``units``, ``errors`` (:class:`~flatcontact.foundation.errors.InputError`), ``limits``
(``FLATCONTACT_MAX_*`` size bounds), ``numbers`` (the bounded float type of every user float),
``interrupts`` (SIGTERM unwinds like Ctrl-C), ``fileio`` (atomic, link-refusing writes; checked
reads; the one file hash), ``result_json`` (the checked reader of each stage's JSON file),
``rundir`` (fingerprinted stage folders, one-writer lock) and ``codegraph`` (the static import
graph). The run settings, also foundation, are the sibling package :mod:`flatcontact.config`.
Nothing here imports from a higher layer (tests/test_architecture.py).
"""
