"""The objects :func:`~mocapqa.api.app.create_app` keeps on ``app.state``, read back typed."""

from __future__ import annotations

from typing import TypeVar

from starlette.requests import HTTPConnection

__all__ = ["app_state"]

T = TypeVar("T")


def app_state(connection: HTTPConnection, name: str, kind: type[T]) -> T:
    """``app.state.<name>`` of the app serving ``connection``, checked to be a ``kind``.

    Raises
    ------
    RuntimeError
        When the app was not made by ``create_app`` (the attribute holds something else).
    """
    value = getattr(connection.app.state, name)
    if not isinstance(value, kind):  # pragma: no cover - set by create_app
        raise RuntimeError(f"app.state.{name} is not set")
    return value
