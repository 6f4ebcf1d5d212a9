"""The parts of a form body, checked against what the route reads, before the route runs.

FastAPI reads a route's declared form fields and ignores the rest; of a field sent twice
where one is read, Starlette keeps the last. So an upload with a second ``file`` part, or
with run options sent as form fields, used to be stored as if they were not there. And a
multipart body the parser refuses was Starlette's bare 400 ("Invalid multipart data.").
:func:`check_form_parts` (a dependency of every route, a no-op for most) and
:func:`multipart_refusal` (for the error handler) make each of these a 422 naming the field,
``body.NAME`` as FastAPI names a body field:

* a route that reads a form gets only the parts it declares: another part is refused naming
  it, and a second part for a field that takes one (``file``) too; a field declared as a list
  (``files`` of a shoot import) takes every part;
* an uploaded file's name is at most :data:`~mocapqa.jobs.take_reading.MAX_NAME_CHARS` characters;
  one too long for the parser to read (a part header over python-multipart's limit, 4224
  bytes in 0.0.34) is refused naming the route's file field;
* a route that reads JSON refuses form fields (run options sent as a form), naming each
  (:func:`form_sent_for_json`, from the validation handler, so a 401 or 403 comes first).
"""

from __future__ import annotations

import re
import types
from collections import Counter
from collections.abc import Sequence
from typing import Any, Union, get_args, get_origin

from fastapi import Request, params
from fastapi.exceptions import RequestValidationError
from starlette.datastructures import FormData, UploadFile
from starlette.exceptions import HTTPException
from starlette.formparsers import MultiPartException
from starlette.requests import HTTPConnection

from mocapqa.jobs.take_reading import MAX_NAME_CHARS, name_too_long

__all__ = [
    "FORM_TYPES",
    "check_form_parts",
    "file_fields",
    "form_sent_for_json",
    "multipart_refusal",
    "reads_form",
    "takes_many",
]

FORM_TYPES = ("multipart/form-data", "application/x-www-form-urlencoded")
"""Content types whose body is a form."""
_ECHO_CHARS = 100
"""Most characters of a client-given part name echoed in an error."""


def takes_many(annotation: Any) -> bool:
    """Whether a field's annotation is a list (or other sequence), optional or not."""
    origin = get_origin(annotation)
    if origin in (Union, types.UnionType):
        return any(takes_many(arg) for arg in get_args(annotation) if arg is not type(None))
    return origin in (list, tuple, set, frozenset, Sequence)


def _body_params(dependant: Any) -> list[Any]:
    """The body fields of a route and of its dependencies."""
    found = list(dependant.body_params)
    for sub in dependant.dependencies:
        found += _body_params(sub)
    return found


def reads_form(route: Any) -> bool | None:
    """True when the route reads a form body, False for a JSON body, None for no body."""
    body = getattr(route, "body_field", None)
    if body is None or getattr(route, "dependant", None) is None:
        return None
    return isinstance(body.field_info, params.Form)


def file_fields(route: Any) -> list[str]:
    """The names of the route's file fields (``File()``), in declaration order."""
    if not reads_form(route):
        return []
    return [p.alias for p in _body_params(route.dependant) if isinstance(p.field_info, params.File)]


def _shown(name: str) -> str:
    return name if len(name) <= _ECHO_CHARS else f"{name[:_ECHO_CHARS]}…"


def _form_problems(
    form: FormData, declared: dict[str, bool], files: Sequence[str] = ()
) -> list[tuple[str, str]]:
    """(field, message) for each part the route does not read, each field sent more often
    than it reads, each file part (``files``) sent without a file name and each file name
    over the limit."""
    problems: list[tuple[str, str]] = []
    for name in files:
        if any(isinstance(value, str) for value in form.getlist(name)):
            # A part whose Content-Disposition has no filename (left out, or only the RFC 5987
            # filename*) reaches the route as text: "Expected UploadFile, received: str".
            problems.append(
                (
                    name,
                    f"Expected a {name!r} part with a file name (Content-Disposition "
                    f'filename="take.bvh"), got a part without one (filename* alone is not read)',
                )
            )
    counts = Counter(name for name, _ in form.multi_items())
    expected = ", ".join(declared)
    for name, count in counts.items():
        if name not in declared:
            problems.append(
                (_shown(name), f"Expected only the form fields {expected}, got {_shown(name)!r}")
            )
        elif count > 1 and not declared[name]:
            problems.append((name, f"Expected one {name!r} part, got {count}"))
    for name, value in form.multi_items():
        if name in declared and isinstance(value, UploadFile) and value.filename:
            too_long = name_too_long(value.filename)
            if too_long is not None:
                problems.append((name, too_long))
    return problems


async def check_form_parts(connection: HTTPConnection) -> None:
    """Refuse (422 naming ``body.NAME``) the parts a form route would not read (see the
    module notes); nothing for a route that reads no form (or a WebSocket).

    Raises
    ------
    RequestValidationError
    """
    route: Any = connection.scope.get("route")
    if not isinstance(connection, Request) or not reads_form(route):
        return
    request = connection
    declared = {p.alias: takes_many(p.field_info.annotation) for p in _body_params(route.dependant)}
    problems = _form_problems(await request.form(), declared, file_fields(route))
    if problems:
        raise RequestValidationError(
            [{"loc": ("body", f), "msg": m, "type": "value_error"} for f, m in problems]
        )


async def form_sent_for_json(request: Request) -> list[tuple[str, str]]:
    """(``body.NAME``, message) for each form field of a form body sent to a route that
    reads JSON (run options sent as a form), or [] when the body is not a form. For the
    validation handler, after the route's other dependencies (401 and 403 come first)."""
    kind = request.headers.get("content-type", "").split(";")[0].strip().lower()
    if kind not in FORM_TYPES or reads_form(request.scope.get("route")) is not False:
        return []
    # The body FastAPI already read, parsed as a form; a multipart body the parser refuses
    # raises its 400 here, which the outer handler answers as multipart_refusal says.
    form = await request.form()
    message = "Expected it in a JSON body (Content-Type: application/json), got a form field"
    return [(f"body.{_shown(name)}", message) for name in dict.fromkeys(form.keys())]


def multipart_refusal(error: HTTPException, route: Any) -> tuple[str, str] | None:
    """The field (``body.NAME`` or ``body``) and an "Expected …, got …" message for a
    multipart body the parser refused (Starlette's 400), or None for another error.

    A part header over the parser's limit is in practice a file name (the only header a
    client fills with its own text), so it is reported against the route's first file field.
    """
    refusal = error.__context__
    if error.status_code != 400 or not isinstance(refusal, MultiPartException):
        return None
    files = file_fields(route)
    field = f"body.{files[0]}" if files else "body"
    reason = str(refusal.__cause__ or "")
    if "header size" in reason:
        return field, (
            f"Expected a file name of at most {MAX_NAME_CHARS} characters, got one too long "
            "for the multipart parser to read (its part header is over the parser's limit)"
        )
    if refusal.message.startswith("Too many files"):
        most = re.search(r"\d+", refusal.message)
        return field, (
            f"Expected at most {most.group() if most else 'the parser allows'} files in one "
            "request, got more (send the rest in another request)"
        )
    return "body", f"Expected a multipart/form-data body the parser reads, got: {refusal.message}"
