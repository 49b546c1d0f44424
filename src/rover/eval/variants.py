"""Variants: one (method, backend, frame count, window, view) combination of a sweep.

A variant's id is stable (the same options always give the same id) and file-name safe,
because it names the trace, judgement and QA files of every episode it ran on, and a
resumed run finds finished work by those names.
"""

from __future__ import annotations

import hashlib
import re
from itertools import product
from typing import Any

from pydantic import BaseModel, Field

from rover.errors import InputError
from rover.methods.info import WINDOW_METHODS, method_info

# methods whose behaviour depends on the sliding-window size (App. M) and their default
# come from the method registry (rover.methods.info)
DEFAULT_WINDOW = 3
_SLUG_MAX = 40


class Variant(BaseModel):
    """One configuration every episode is run with."""

    id: str
    method: str
    backend: str  # backend spec, e.g. "oracle", "openai:gpt-4o"
    frames: int | None = None  # None: the episode's own frames
    window: int | None = None  # None: the method takes no window
    view: str | None = None  # None: the episode's default view
    params: dict[str, Any] = Field(default_factory=dict)  # passed to get_method
    label: str = ""  # short display name, unique within a run


def backend_slug(spec: str) -> str:
    """File-name-safe form of a backend spec ('openai:gpt-4o@http://h:8000/v1' -> ...)."""
    from rover.eval.runconfig import scrub_text

    spec = scrub_text(spec.strip())
    slug = re.sub(r"[^A-Za-z0-9._-]+", "-", spec).strip("-.") or "backend"
    if len(slug) > _SLUG_MAX:
        digest = hashlib.sha256(spec.encode()).hexdigest()[:6]
        slug = f"{slug[: _SLUG_MAX - 7]}-{digest}"
    return slug


def variant_id(
    method: str, backend: str, frames: int | None, window: int | None, view: str | None
) -> str:
    """'<method>__b=<slug>__f=<n|all>__w=<n|na>__v=<view|default>'."""
    view_part = re.sub(r"[^A-Za-z0-9._-]+", "-", view) if view else "default"
    return (
        f"{method}__b={backend_slug(backend)}__f={frames if frames else 'all'}"
        f"__w={window if window is not None else 'na'}__v={view_part}"
    )


def expand_variants(
    methods: list[str],
    backends: list[str],
    frames: list[int | None],
    windows: list[int | None],
    views: list[str | None],
    method_params: dict[str, dict[str, Any]] | None = None,
) -> list[Variant]:
    """Every combination, in a stable order; windows apply only to windowed methods.

    `method_params` adds fixed parameters for one method in every variant (for example
    clip-value's `model_path`); they do not enter the variant id.
    """
    if not methods:
        raise InputError("--methods: give at least one method")
    if not backends:
        raise InputError("--backend: give at least one backend spec")
    out: list[Variant] = []
    seen: set[str] = set()
    for method, backend, n, w, view in product(methods, backends, frames, windows, views):
        window = (w or method_info(method).default_window) if method in WINDOW_METHODS else None
        vid = variant_id(method, backend, n, window, view)
        if vid in seen:
            continue
        seen.add(vid)
        params = {"window": window} if window is not None else {}
        params.update((method_params or {}).get(method, {}))
        out.append(
            Variant(
                id=vid,
                method=method,
                backend=backend,
                frames=n,
                window=window,
                view=view,
                params=params,
            )
        )
    _label(out)
    return out


def _label(variants: list[Variant]) -> None:
    """Display name plus the settings that vary within this run ('ROVER (window 6) · 30
    frames'). The view is not part of it: views are a column of their own in every table."""
    backends = {v.backend for v in variants}
    frames = {v.frames for v in variants}
    for v in variants:
        info = method_info(v.method)
        name = info.display
        if v.window is not None and v.window != info.default_window:
            name += f" (window {v.window})"
        if len(backends) > 1:
            name += f" [{v.backend}]"
        if len(frames) > 1:
            name += f" · {v.frames} frames" if v.frames else " · all frames"
        v.label = name


def parse_int_list(text: str | None, option: str, minimum: int = 1) -> list[int | None]:
    """'30,60' -> [30, 60]; None -> [None]; bad values -> one-line InputError."""
    if text is None or not str(text).strip():
        return [None]
    out: list[int | None] = []
    for item in str(text).split(","):
        item = item.strip()
        if item.lower() in ("all", "default"):
            out.append(None)
            continue
        try:
            value = int(item)
        except ValueError:
            raise InputError(f"{option}: {item!r} is not a whole number") from None
        if value < minimum:
            raise InputError(f"{option}: {value} is below the minimum of {minimum}")
        out.append(value)
    return list(dict.fromkeys(out))


def parse_name_list(text: str | None, option: str) -> list[str]:
    """'a, b,a' -> ['a', 'b'] (order kept, duplicates dropped)."""
    items = [x.strip() for x in str(text or "").split(",") if x.strip()]
    if not items:
        raise InputError(f"{option}: give at least one value")
    return list(dict.fromkeys(items))


def split_backend_specs(text: str) -> list[str]:
    """Comma-separated backend specs; a comma inside a URL query is not expected.

    An item that is a bare URL (`http://...`) is one more replica of the spec before it
    (an endpoint pool: `openai:m@http://a/v1,http://b/v1`), not a backend of its own.
    """
    specs: list[str] = []
    items = [x.strip() for x in str(text or "").split(",") if x.strip()]
    if not items:
        raise InputError("--backend: give at least one value")
    for item in items:
        if specs and item.lower().startswith(("http://", "https://")):
            specs[-1] += "," + item
        else:
            specs.append(item)
    return list(dict.fromkeys(specs))
