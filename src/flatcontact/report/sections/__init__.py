"""The report's sections, one module per stage; :mod:`flatcontact.report.assemble` orders them.

Each section is a function of the stage's results (its JSON document, ``friction.csv``) and
folder (its figures, named in :mod:`flatcontact.foundation.layout`) returning a
:class:`~flatcontact.report.html.Section`.
"""
