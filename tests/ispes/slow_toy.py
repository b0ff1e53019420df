"""The toy calculator, slowed down so that a scan lasts long enough to kill a worker in it.

A module of its own so that ``dask worker`` processes import it by name
(``tests.ispes.slow_toy:slow_toy``), with the repository root on their ``PYTHONPATH``.
"""

import time

from flatcontact.ispes.toy import toy_calculator


def slow_toy(atoms, delay_s=0.004):
    calc = toy_calculator(atoms)
    inner = calc.calculate

    def calculate(*args, **kwargs):
        time.sleep(delay_s)
        return inner(*args, **kwargs)

    calc.calculate = calculate
    return calc
