"""Adapters that put the stack's cores behind the offline replay harness.

Each adapter does what its node does, without DDS: convert subscribed messages into
the core's inputs and step the core at the node's rate. Only cores that import are
offered (``factories``); a core still missing is named by ``missing``.
"""
from __future__ import annotations

from typing import Callable

from dukw_bringup.replay import CoreAdapter

#: adapter name -> (module that must import, factory)
_REGISTRY: dict[str, tuple[str, Callable[[], CoreAdapter]]] = {}
_MISSING: dict[str, str] = {}


def _register(name: str, module: str):
    def wrap(factory: Callable[[], CoreAdapter]) -> Callable[[], CoreAdapter]:
        _REGISTRY[name] = (module, factory)
        return factory
    return wrap


def factories() -> dict[str, Callable[[], CoreAdapter]]:
    """Factories of the adapters whose core imports."""
    import importlib
    out = {}
    for name, (module, factory) in _REGISTRY.items():
        try:
            importlib.import_module(module)
        except ImportError as exc:
            _MISSING[name] = str(exc)
            continue
        out[name] = factory
    return out


def missing() -> dict[str, str]:
    """Adapters whose core did not import, with the reason."""
    factories()
    return dict(_MISSING)
