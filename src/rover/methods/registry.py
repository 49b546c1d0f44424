"""Method registry: names as used on the command line and in evaluation configs."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from rover.errors import InputError
from rover.methods.base import Method
from rover.methods.info import NON_VLM_METHODS as _NON_VLM
from rover.methods.info import MethodInfo, method_info

__all__ = ["NON_VLM_METHODS", "MethodInfo", "get_method", "method_info", "method_names"]


def _factories() -> dict[str, Callable[..., Method]]:
    from rover.methods.clip_value import ClipValue
    from rover.methods.concat import LocalConcat, TemporalConcat, VideoConcat
    from rover.methods.gvl import GVL, GVLSingle
    from rover.methods.rover import Rover, RoverNoRecursion, RoverNoWindow

    classes = [
        Rover,
        RoverNoWindow,
        RoverNoRecursion,
        GVL,
        GVLSingle,
        TemporalConcat,
        LocalConcat,
        VideoConcat,
        ClipValue,
    ]
    return {c.name: c for c in classes}


def method_names() -> list[str]:
    """Every registered method name, ROVER and its ablations first."""
    return list(_factories())


# methods that only look at pixels through an embedding model: no VLM calls, no tokens
NON_VLM_METHODS = _NON_VLM


def vlm_method_names() -> list[str]:
    """The methods that reason through a VLM (everything the oracle demo can run)."""
    return [m for m in method_names() if m not in NON_VLM_METHODS]


def get_method(name: str, **params: Any) -> Method:
    """A configured method; unknown names list the valid ones.

    Parameters a method does not use (e.g. `window` for GVL) are ignored, so one set of
    options can be passed to every method in a sweep.
    """
    factories = _factories()
    if name not in factories:
        raise InputError(f"unknown method {name!r}; valid methods: {', '.join(factories)}")
    params = {k: v for k, v in params.items() if v is not None}
    try:
        return factories[name](**params)
    except TypeError as exc:
        raise InputError(f"method {name!r}: bad parameters ({exc})") from exc
