"""Robust LQR (placeholder while the implementation lands)."""
from dataclasses import dataclass


@dataclass(frozen=True)
class RLQRBatch:
    pass


def rlqr(plant, EF, EG, mu, **kwargs):
    raise NotImplementedError


def rlqr_gains(plant, EF, EG, mu, **kwargs):
    raise NotImplementedError
