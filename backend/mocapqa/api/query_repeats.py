"""Query parameters sent more than once where the route reads one value.

Starlette keeps the last of a repeated query parameter (``?limit=5&limit=100000``), so what a
client meant, and what a proxy or log in front of the server saw, could differ from what the
route used. :func:`check_query_repeats` (a dependency of every route) refuses such a request
with a 422 naming ``query.NAME``, as FastAPI names a query field; a parameter declared as a
list takes every value.
"""

from __future__ import annotations

from collections import Counter
from typing import Any

from fastapi.exceptions import RequestValidationError
from starlette.requests import HTTPConnection

from mocapqa.api.form_parts import takes_many

__all__ = ["check_query_repeats"]


def _query_params(dependant: Any) -> list[Any]:
    """The query fields of a route and of its dependencies."""
    found = list(dependant.query_params)
    for sub in dependant.dependencies:
        found += _query_params(sub)
    return found


async def check_query_repeats(connection: HTTPConnection) -> None:
    """Refuse (422 naming ``query.NAME``) a query parameter given more than once where the
    route reads one; nothing for a route without query parameters.

    Raises
    ------
    RequestValidationError
    """
    dependant = getattr(connection.scope.get("route"), "dependant", None)
    if dependant is None:
        return
    counts = Counter(name for name, _ in connection.query_params.multi_items())
    repeated = [name for name, count in counts.items() if count > 1]
    if not repeated:
        return
    single = {p.alias for p in _query_params(dependant) if not takes_many(p.field_info.annotation)}
    problems = [
        {
            "loc": ("query", name),
            "msg": f"Expected one {name!r} query parameter, got {counts[name]}",
            "type": "value_error",
        }
        for name in repeated
        if name in single
    ]
    if problems:
        raise RequestValidationError(problems)
