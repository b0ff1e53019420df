"""The reference interface's Hessian of a scan: computed once, in the driver, used everywhere.

Every preconditioned point of a scan starts its L-BFGS from L = H0^{1/2} of the reference
interface (:mod:`flatcontact.ispes.precondition`). :class:`HessianSharing` computes L once per
scan attempt, in the driver, with the driver's calculator, before anything relaxes (2 force
calls per relaxed coordinate: :attr:`HessianSharing.hessian_force_calls`, ``scan.json``
``hessian_force_calls``), and hands those bits to every process that relaxes the scan's points:
the probe's chains and segments, the ideal work of separation, the grid, its verification and
extensions (their tasks carry a :class:`~flatcontact.ispes.precondition.SharedRoot`, a few
strings, never the n × n matrix; :func:`flatcontact.ispes.relax.context_calculator` gives it
to the process's calculator). A root computed by each worker instead would cost every worker
its own Hessian, and could differ from the driver's in the last bits (a worker runs one BLAS
thread, the driver the default), and with it the points that worker relaxed.

How the bits travel, by executor
--------------------------------
``inline`` (the serial executor)
    The tasks run in the driver, whose calculator holds the root.
Dask (an executor with ``setup_workers``: :class:`flatcontact.ispes.executors.DaskExecutor`)
    A worker plugin gives the root to every worker once, to those that join later too, and
    to workers on other machines that cannot read the driver's folder
    (:func:`flatcontact.ispes.precondition.receive_root` checks its digest there); withdrawn
    when the scan ends. Every Dask worker relaxes with the driver's bits.
local worker processes (any other executor)
    A hidden file in the scan's folder, ``.reference-hessian-<key>.npy`` (``<key>``: the start
    of the SHA-256 of the model's fingerprint, the mode, the reference and its held atoms),
    written atomically. Each process reads it at its first task that needs it and checks it
    against the size and SHA-256 the task names (:func:`~flatcontact.ispes.precondition.shared_root`),
    so a worker that missed the executor's prestart still gets the driver's bits, and a file
    a killed run left behind is never trusted (the driver writes its own over it before any
    task names it). A process that finds no root it can check fails its task: it never
    computes one of its own.

The file is removed when the scan ends (normally, on an error or on Ctrl-C), with any other
``.reference-hessian-*.npy`` a killed driver left in the folder (the store's one-writer lock
makes the folder this driver's). Nothing is written outside the scan's folder.

The fold re-relaxation after the scan (:mod:`flatcontact.ispes.rerelax`) runs in the driver's
process, whose calculator keeps the root; run in another process, it computes the same K and,
with the driver's BLAS threads, the same root.
"""

from __future__ import annotations

import contextlib
import hashlib
from pathlib import Path
from typing import Any

import numpy as np
from ase import Atoms

from flatcontact.foundation.fileio import atomic_path
from flatcontact.ispes import precondition
from flatcontact.ispes.geometry import fixed_mask
from flatcontact.ispes.relax import (
    RelaxSettings,
    ScanContext,
    constraint_projector,
    reference_root,
    worker_calculator,
)
from flatcontact.potentials.guarded import failing_at

#: the hidden file's name in the scan's folder: this prefix, 16 hex digits of the key, ``.npy``
FILE_PREFIX = ".reference-hessian-"


def shared_key(reference: Atoms, factory: Any, mode: str) -> str:
    """SHA-256 (hex) of what the reference's root is a function of: the model's fingerprint,
    the relaxation ``mode``, the reference interface and its held atoms."""
    digest = hashlib.sha256(str(factory.fingerprint).encode())
    for part in precondition.root_key(reference, fixed_mask(reference), mode):
        digest.update(part.encode() if isinstance(part, str) else part)
    return digest.hexdigest()


class HessianSharing:
    """The root of one scan's reference Hessian, computed in the driver when first asked for.

    Parameters
    ----------
    out_dir
        The scan's folder (the hidden file of local worker processes goes there).
    reference, factory, relax
        The scan's reference interface, calculator factory and relaxation settings.

    Use as a context manager around everything that submits the scan's tasks: leaving it
    removes the file and withdraws the Dask plugin.
    """

    def __init__(self, out_dir: str | Path, reference: Atoms, factory: Any, relax: RelaxSettings):
        self.out_dir = Path(out_dir)
        self.reference, self.factory, self.relax = reference, factory, relax
        #: force calls the driver spent on the Hessian in this attempt (0 if not needed or
        #: already computed by this process for the same calculator, reference and mode)
        self.hessian_force_calls = 0
        self._context: ScanContext | None = None
        self._withdraw: tuple[Any, str] | None = None

    def plain_context(self) -> ScanContext:
        """The context of tasks that relax nothing (the overlap check, a finished store)."""
        return self._context or ScanContext(self.reference, self.factory, self.relax)

    def context(self, executor: Any) -> ScanContext:
        """The scan's :class:`~flatcontact.ispes.relax.ScanContext` with the driver's root
        (``hessian``; None where the settings or the cell's size take no preconditioner),
        computed and handed to ``executor``'s processes at the first call."""
        if self._context is None:
            shared = self._share(executor)
            self._context = ScanContext(self.reference, self.factory, self.relax, shared)
        return self._context

    def _share(self, executor: Any) -> precondition.SharedRoot | None:
        reference, relax = self.reference, self.relax
        if not relax.uses_reference_hessian:
            return None
        calc = worker_calculator(self.factory, reference)  # the driver's own
        fixed = fixed_mask(reference)
        before = calc.force_calls
        with failing_at("the reference interface's Hessian"):
            root = reference_root(
                reference,
                calc,
                fixed,
                relax.mode,
                constraint_projector(fixed, relax.mode, []),
                between_columns=getattr(executor, "serve", None),  # the workers fed meanwhile
            )
        self.hessian_force_calls += calc.force_calls - before
        if root is None:
            return None
        sha = precondition.root_sha256(root)
        root = precondition.receive_root(root, sha)  # the driver's other threads too
        key = shared_key(reference, self.factory, relax.mode)
        path = None
        setup_workers = getattr(executor, "setup_workers", None)
        if executor.inline:
            pass
        elif setup_workers is not None:
            name = f"flatcontact-reference-hessian-{sha[:16]}"
            self._withdraw = (executor, name)
            setup_workers(name, precondition.receive_root, root, sha)
        else:
            path = str(self._write(root, key))
        return precondition.SharedRoot(key, sha, int(root.shape[0]), path)

    def _write(self, root: np.ndarray, key: str) -> Path:
        """The root into the hidden file of ``key`` (atomically), any stale one removed."""
        self.remove_files()
        target = (self.out_dir / f"{FILE_PREFIX}{key[:16]}.npy").absolute()
        with atomic_path(target) as tmp, open(tmp, "wb") as handle:
            np.save(handle, root, allow_pickle=False)
        return target

    def remove_files(self) -> None:
        """Remove every ``.reference-hessian-*.npy`` of the scan's folder."""
        if self.out_dir.is_dir():
            for path in self.out_dir.glob(f"{FILE_PREFIX}*.npy"):
                path.unlink(missing_ok=True)

    def close(self) -> None:
        """Remove the file, withdraw the Dask plugin (if its client is still open)."""
        self.remove_files()
        if self._withdraw is not None:
            executor, name = self._withdraw
            self._withdraw = None
            with contextlib.suppress(Exception):
                executor.withdraw_setup(name)

    def __enter__(self) -> HessianSharing:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()
