"""`twin view` and `twin snapshot`: the server hosts the viewer and renders; this side only asks.

Client-side like the world commands: neither mujoco nor the viewer is imported here (the server
owns the model and data, so it hosts the page and renders the pictures).
"""

from __future__ import annotations

import sys
import webbrowser
from pathlib import Path
from typing import Annotated

import typer

from twin_cli.cli.options import JsonOpt, WorldOpt
from twin_cli.cli.output import Output

QUALITIES = ("auto", "full", "fast")  # the server's `twin_cli.view.look.QUALITIES`

HostOpt = Annotated[
    str,
    typer.Option(help="Address to listen on (default 127.0.0.1: this machine only)."),
]


def view(
    world: WorldOpt = "default",
    port: Annotated[int, typer.Option(help="Port (0: the first free one from 8080).")] = 0,
    host: HostOpt = "127.0.0.1",
    open_page: Annotated[bool, typer.Option("--open", help="Open the page in a browser.")] = False,
    stop: Annotated[bool, typer.Option("--stop", help="Close the viewer.")] = False,
    quality: Annotated[
        str | None,
        typer.Option(
            metavar="[auto|full|fast]",
            help="The page's look: full (shadows, multisampling), fast (neither: 2-3x quicker "
            "frames in a browser without a GPU), auto (fast once a page renders in software). "
            "Default: auto, or what the running viewer has.",
        ),
    ] = None,
    json: JsonOpt = False,
) -> None:
    """Show the running world in MuJoCo's web viewer (like gzclient); prints the page's URL.

    The page can pause, run and reset the world and push bodies (Ctrl+drag). It answers only
    requests for its own address from its own pages; with --host other than loopback the page
    also needs a token, which the printed URL carries: anyone with that URL who reaches the
    port can drive the world.
    """
    from twin_cli.errors import InvalidRequestError
    from twin_cli.server.connection import connect

    if quality is not None and quality not in QUALITIES:
        raise InvalidRequestError(
            f"--quality [{quality}]", "unknown", f"use one of {', '.join(QUALITIES)}"
        )
    if quality is not None and stop:
        raise InvalidRequestError(
            "--quality with --stop", "there is no page to set it for", "give one or the other"
        )
    with connect(world) as client:
        if stop:
            reply = client.request("DELETE", "/view")
        else:
            body = {"host": host, "port": port, "quality": quality}
            reply = client.request("POST", "/view", body=body)
    out = Output(json)
    if json:
        out.data(reply)
        return
    if stop:
        out.line(f"closed the viewer at {reply['stopped']}")
        return
    if reply.get("warning"):
        sys.stderr.write(f"twin: warning: {reply['warning']}\n")
    look = reply.get("look") or {}
    if look.get("fast"):
        why = f"a page renders with {look['software']}" if look.get("software") else "asked"
        sys.stderr.write(f"twin: the page gets the fast look (no shadows): {why}\n")
    out.line(reply["url"])
    if open_page:
        webbrowser.open(reply["url"], new=2)


def snapshot(
    out: Annotated[Path, typer.Argument(help="The PNG file to write (OUT.png).")],
    entity: Annotated[
        str | None, typer.Option(help="Aim at this entity (default: the whole scene).")
    ] = None,
    width: Annotated[int, typer.Option(help="Width in pixels.")] = 640,
    height: Annotated[int, typer.Option(help="Height in pixels.")] = 480,
    force: Annotated[
        bool, typer.Option("--force", help="Replace OUT even if twin did not write it.")
    ] = False,
    world: WorldOpt = "default",
    json: JsonOpt = False,
) -> None:
    """Render the running world offscreen into a PNG (no browser or display needed)."""
    from twin_cli.server.connection import connect

    body = {
        "path": str(out.expanduser().resolve()),
        "entity": entity,
        "width": width,
        "height": height,
        "force": force,
    }
    with connect(world) as client:  # a first render starts GL: wait while the server lives
        reply = client.long_request(
            "POST", "/snapshot", body=body, what=f"snapshot {body['path']}", repeat="twin snapshot"
        )
    sink = Output(json)
    if json:
        sink.data(reply)
    else:
        sink.line(f"{reply['path']}: {width}x{height} PNG")


def register(app: typer.Typer) -> None:
    """Add `twin view` and `twin snapshot` to the `twin` app."""
    app.command("view")(view)
    app.command("snapshot")(snapshot)
