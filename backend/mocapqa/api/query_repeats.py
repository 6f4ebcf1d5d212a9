"""Query parameters and JSON keys sent more than once where the route reads one value.

Starlette keeps the last of a repeated query parameter (``?limit=5&limit=100000``), and
Python's JSON parser the last of a repeated key (``{"name": "a", "name": "b"}``), so what a
client meant, and what a proxy or log in front of the server saw, could differ from what the
route used. :func:`check_query_repeats` refuses such a query with a 422 naming
``query.NAME``, as FastAPI names a query field (a parameter declared as a list takes every
value); :func:`check_json_repeats` a JSON body with a key given twice in one object, naming
``body.KEY``. Both are dependencies of every route.
"""

from __future__ import annotations

import json
from collections import Counter
from typing import Any

from fastapi.exceptions import RequestValidationError
from starlette.requests import HTTPConnection, Request

from mocapqa.api.form_parts import reads_form, takes_many
from mocapqa.core.json_keys import RepeatedKeyError, unique_keys

__all__ = ["check_json_repeats", "check_query_repeats"]


async def check_json_repeats(connection: HTTPConnection) -> None:
    """Refuse (422 naming ``body.KEY``) a JSON body with a key given twice in one object; a
    body that is not valid JSON is left to FastAPI's own 422.

    Raises
    ------
    RequestValidationError
    """
    if (
        not isinstance(connection, Request)
        or reads_form(connection.scope.get("route")) is not False
    ):
        return
    kind = connection.headers.get("content-type", "").split(";")[0].strip().lower()
    if not kind.endswith("json"):
        return
    body = await connection.body()  # cached: the route reads the same bytes
    try:
        json.loads(body, object_pairs_hook=unique_keys)
    except RepeatedKeyError as e:
        shown = e.key if len(e.key) <= 100 else f"{e.key[:100]}…"
        raise RequestValidationError(
            [
                {
                    "loc": ("body", shown),
                    "msg": f"Expected each key once, got {shown!r} twice",
                    "type": "value_error",
                }
            ]
        ) from None
    except (ValueError, RecursionError):  # not JSON: FastAPI answers it
        return


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
