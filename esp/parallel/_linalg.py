"""Batched linear algebra that survives a singular matrix in the batch."""

from __future__ import annotations

import contextlib

import numpy as np

__all__ = ["solve"]


def solve(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``np.linalg.solve(a, b)`` for stacks of matrices; a singular matrix of the stack
    gives NaN in its place instead of failing the whole stack (callers mask or refuse such
    poses by their condition number)."""
    try:
        return np.linalg.solve(a, b)
    except np.linalg.LinAlgError:
        out = np.full(np.broadcast_shapes(a.shape[:-2], b.shape[:-2]) + b.shape[-2:], np.nan)
        a_b = np.broadcast_to(a, out.shape[:-2] + a.shape[-2:])
        b_b = np.broadcast_to(b, out.shape)
        for idx in np.ndindex(out.shape[:-2]):
            with contextlib.suppress(np.linalg.LinAlgError):
                out[idx] = np.linalg.solve(a_b[idx], b_b[idx])
        return out
