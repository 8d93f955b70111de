"""The world server's error replies: one JSON body for every failure, a status per error class.

A TwinError or ConversionError keeps its class name, so the client raises the same class again
with the server's message; validation, HTTP, file and unexpected errors are said the same way.
The server and its world keep running after any of them.
"""

from __future__ import annotations

import logging
from typing import Any

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from pydantic import BaseModel
from starlette.exceptions import HTTPException as StarletteHTTPException

from converters.errors import ConversionError
from twin_cli.errors import (
    EntityExistsError,
    EntityNotFoundError,
    PartNotFoundError,
    RequestError,
    TopicNotFoundError,
    TwinError,
)

log = logging.getLogger("twin.server")

# Status of each error class; other TwinError and ConversionError subclasses are 400.
ERROR_STATUS: dict[type[Exception], int] = {
    EntityNotFoundError: 404,
    PartNotFoundError: 404,
    TopicNotFoundError: 404,
    EntityExistsError: 409,
}


class ErrorBody(BaseModel):
    """Every error reply: the error's class (the client raises it again) and one message."""

    error: str
    message: str


# Documented on every operation, so the OpenAPI schema is the whole contract (422 included:
# validation errors use this body too, not FastAPI's default).
ERROR_RESPONSES: dict[int | str, dict[str, Any]] = {
    status: {"model": ErrorBody, "description": text}
    for status, text in (
        (400, "bad request: the message names the value and the fix"),
        (401, "TCP request without the bearer token"),
        (404, "no such entity, joint, link, sensor or topic"),
        (409, "the name is taken"),
        (413, "the request body is over the server's limit"),
        (422, "the body does not match the request schema"),
        (500, "internal error; the world keeps running"),
    )
}


def error_reply(status: int, name: str, message: str) -> JSONResponse:
    """The error body every failure is answered with."""
    return JSONResponse(status_code=status, content={"error": name, "message": message})


def _known_error(request: Request, exc: Exception) -> JSONResponse:
    """TwinError/ConversionError: the class name and its message (what, where, fix)."""
    status = next((s for cls, s in ERROR_STATUS.items() if isinstance(exc, cls)), 400)
    log.info(
        "%s %s -> %d %s: %s", request.method, request.url.path, status, type(exc).__name__, exc
    )
    return error_reply(status, type(exc).__name__, str(exc))


def _validation_error(request: Request, exc: RequestValidationError) -> JSONResponse:
    """pydantic's findings as one line naming each bad field."""
    problems = "; ".join(
        f"{'.'.join(str(p) for p in err['loc'] if p != 'body') or 'body'}: "
        f"{err['msg'].removeprefix('Value error, ')}"
        for err in exc.errors()
    )
    message = str(
        RequestError(
            f"{request.method} {request.url.path}",
            problems,
            "see docs/api.md or /openapi.json for the request schema",
        )
    )
    return error_reply(422, "RequestError", message)


def _http_error(request: Request, exc: StarletteHTTPException) -> JSONResponse:
    """Starlette's own refusals (a body that is not JSON, an unknown path) in twin's error body."""
    message = str(
        RequestError(
            f"{request.method} {request.url.path}",
            str(exc.detail),
            "see docs/api.md or /openapi.json for the request schema",
        )
    )
    return error_reply(exc.status_code, "RequestError", message)


def _os_error(request: Request, exc: OSError) -> JSONResponse:
    """A file the request named cannot be read or written on the server's host."""
    where = exc.filename or request.url.path
    message = str(
        RequestError(
            str(where),
            exc.strerror or str(exc),
            "give a path that exists and is readable on the server's host",
        )
    )
    return error_reply(400, "RequestError", message)


def _value_error(request: Request, exc: ValueError) -> JSONResponse:
    message = str(
        RequestError(
            f"{request.method} {request.url.path}",
            str(exc),
            "check the values against `twin physics`/docs/api.md",
        )
    )
    return error_reply(400, "RequestError", message)


def _unexpected(request: Request, exc: Exception) -> JSONResponse:
    """Any other failure: logged with its traceback; the server and the world keep running."""
    log.exception("%s %s failed", request.method, request.url.path)
    message = str(
        RequestError(
            f"{request.method} {request.url.path}",
            f"internal error {type(exc).__name__}: {exc}",
            "see `twin logs`; the world is still running",
        )
    )
    return error_reply(500, "RequestError", message)


def install_handlers(app: FastAPI) -> None:
    """Answer every kind of failure with `ErrorBody`."""
    app.add_exception_handler(TwinError, _known_error)
    app.add_exception_handler(ConversionError, _known_error)
    app.add_exception_handler(RequestValidationError, _validation_error)
    app.add_exception_handler(StarletteHTTPException, _http_error)
    app.add_exception_handler(OSError, _os_error)
    app.add_exception_handler(ValueError, _value_error)
    app.add_exception_handler(Exception, _unexpected)
