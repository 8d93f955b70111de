"""`twin topics` and `twin topics echo NAME`: the running world's streams, like `gz topic -l`
and `gz topic -e` (or `ros2 topic list -t` and `ros2 topic echo`).

Client-side (no mujoco or numpy): the server names the topics as a recording does and makes
the messages at each topic's rate in sim time (`twin_cli.live`); the echo reads them from one
streamed reply. Ctrl-C or a reader that goes away ends it with exit code 0.
"""

from __future__ import annotations

import json as jsonlib
from typing import Annotated, Any

import typer

from twin_cli.cli.options import JsonOpt, WorldOpt
from twin_cli.cli.output import Output

TRUNCATE = 128  # items of an array, characters of a string (ros2 topic echo's default)
EchoJsonOpt = Annotated[
    bool,
    typer.Option(
        "--json",
        help="Print one JSON object a line per message, streamed until -n N or Ctrl-C (without "
        "-n it never ends); a non-finite number (a lidar ray without a return, `.inf` in the "
        "text) is null.",
    ),
]

app = typer.Typer(
    help="List the running world's topics with type and rate (like `gz topic -l`); "
    "`twin topics echo NAME` prints one as it arrives.",
    no_args_is_help=False,
)


@app.callback(invoke_without_command=True)
def topics(ctx: typer.Context, world: WorldOpt = "default", json: JsonOpt = False) -> None:
    """List every topic the running world offers, with its type and rate (like `gz topic -l`)."""
    if ctx.invoked_subcommand is not None:
        return
    from twin_cli.server.connection import connect

    with connect(world, start=False) as client:
        listing = client.request("GET", "/topics")
    out = Output(json)
    if json:
        out.data(listing)
        return
    rows = [[t["name"], t["type"], _rate(t), t["entity"] or "-"] for t in listing]
    out.table(f"topics of world [{world}]", ["topic", "type", "rate", "entity"], rows)


def _rate(topic: dict[str, Any]) -> str:
    if topic.get("command"):
        return "command (in)"
    return "latched" if topic["latched"] else f"{topic['rate']:g} Hz"


def echo(
    name: Annotated[str, typer.Argument(help="The topic, e.g. /robot/joint_states.")],
    count: Annotated[
        int, typer.Option("-n", "--count", min=0, help="Stop after N messages (0: never).")
    ] = 0,
    rate: Annotated[
        float | None,
        typer.Option("--rate", help="Hz of sim time, for state topics (default: the topic's)."),
    ] = None,
    full_length: Annotated[
        bool, typer.Option("--full-length", help="Print whole arrays and strings.")
    ] = False,
    world: WorldOpt = "default",
    json: EchoJsonOpt = False,
) -> None:
    """Print a topic's messages as they arrive (like `gz topic -e`); `---` between messages."""
    from urllib.parse import urlencode

    from twin_cli.server.connection import connect

    query = {"name": name, "count": count, "truncate": 0 if full_length else TRUNCATE}
    if rate is not None:
        query["rate"] = repr(rate)
    with connect(world, start=False) as client:
        messages = client.stream(f"/topics/echo?{urlencode(query)}")
        try:
            _print(messages, count, Output(json))
        except KeyboardInterrupt:
            return
        finally:
            messages.close()


def _print(messages: Any, count: int, out: Output) -> None:
    from twin_cli.cli.message_text import json_safe, message_text

    for n, item in enumerate(messages, start=1):
        if out.json_mode:  # one compact object per line, as a stream of messages
            out.stream.write(jsonlib.dumps(json_safe(item), allow_nan=False) + "\n")
        else:
            out.stream.write(message_text(item["message"]) + "\n---\n")
        out.stream.flush()
        if count and n >= count:
            return


def register(parent: typer.Typer) -> None:
    """Adds `topics` (with `topics echo`)."""
    app.command("echo")(echo)
    parent.add_typer(app, name="topics")
