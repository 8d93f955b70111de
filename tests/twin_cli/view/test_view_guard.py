"""The viewer and the Foxglove stream guarded like a local daemon: Host, Origin, token, options."""

from __future__ import annotations

import asyncio
import http.client
import os
import socket
import subprocess
import sys
import textwrap
import time

import pytest
import websockets
from websockets.datastructures import Headers
from websockets.exceptions import InvalidStatus
from websockets.http11 import Request

from twin_cli.errors import RequestError
from twin_cli.view.guard import ViewGuard

FOREIGN = "http://evil.example"


def free_port(host: str = "127.0.0.1") -> int:
    with socket.socket() as s:
        s.bind((host, 0))
        return s.getsockname()[1]


def get(address: str, port: int, path: str, **headers: str) -> tuple[int, str | None, bytes]:
    """One GET to `address:port` with exactly these headers (Host included): status, cookie,
    body."""
    conn = http.client.HTTPConnection(address, port, timeout=10)
    try:
        conn.putrequest("GET", path, skip_host=True, skip_accept_encoding=True)
        for name, value in headers.items():
            conn.putheader(name, value)
        conn.endheaders()
        reply = conn.getresponse()
        return reply.status, reply.getheader("Set-Cookie"), reply.read()
    finally:
        conn.close()


def handshake(address: str, port: int, path: str, *, host: str, origin: str | None, **extra: str):
    """A WebSocket opening handshake from a page of `origin`: 101 when it opens, else the status
    the server refused it with."""

    async def run() -> int:
        # The URL names `host` (the Host header), the socket goes to `address`: a DNS-rebound
        # name is exactly that.
        sock = socket.create_connection((address, port), timeout=10)
        try:
            async with websockets.connect(
                f"ws://{host}{path}",
                sock=sock,
                origin=origin,
                additional_headers=extra or None,
                open_timeout=10,
            ):
                return 101
        except InvalidStatus as exc:
            return exc.response.status_code

    return asyncio.run(run())


def test_a_page_from_another_origin_cannot_drive_the_world_through_the_viewer(
    tmp_path, serve_world
):
    port = free_port()
    with serve_world(tmp_path, "viewguard") as (client, _):
        started = client.request("POST", "/view", body={"host": "127.0.0.1", "port": port})
        assert started["url"] == f"http://localhost:{port}/" and not started["token_required"]
        own = f"localhost:{port}"
        # A loopback request with the right Host works (each name of loopback).
        for name in (own, f"127.0.0.1:{port}"):
            status, _, body = get("127.0.0.1", port, "/", Host=name)
            assert status == 200 and b"<!doctype html>" in body.lower(), (name, status, body)
        assert handshake("127.0.0.1", port, "/state?sid=a", host=own, origin=f"http://{own}") == 101
        # A page of another site: its WebSockets (/ui drives the world, /state and /drop too)
        # are refused, and so is a DNS-rebound name pointing at this port.
        for path in ("/ui?sid=b", "/state?sid=b", "/drop?sid=b"):
            assert handshake("127.0.0.1", port, path, host=own, origin=FOREIGN) == 403, path
            rebound = f"evil.example:{port}"
            assert handshake("127.0.0.1", port, path, host=rebound, origin=None) == 403, path
        status, _, body = get("127.0.0.1", port, "/", Host=f"evil.example:{port}")
        assert status == 403 and b"not this viewer's address" in body, body
        status, _, body = get("127.0.0.1", port, "/model", Host=own, Origin=FOREIGN)
        assert status == 403 and b"Origin" in body, body
        time.sleep(0.3)
        stats = client.request("GET", "/stats")
        assert stats["paused"] is False and stats["sim_time"] > 0, stats

        # Other options while the viewer runs: 409 naming the running viewer and the fix.
        other = client._http.request("POST", "/view", json={"host": "127.0.0.1", "port": port + 1})
        assert other.status_code == 409, other.text
        message = other.json()["message"]
        assert f"127.0.0.1:{port}" in message and "twin view --stop" in message, message
        assert f"--port {port}" in message, message
        again = client.request("POST", "/view", body={"host": "127.0.0.1", "port": 0})
        assert again["url"] == started["url"], "the same options must show the running viewer"
        cli = subprocess.run(
            [sys.executable, "-m", "twin_cli.cli.app", "view", "--host", "127.0.0.2",
             "--world", "viewguard"],
            capture_output=True, text=True, timeout=60, env=os.environ.copy(),
        )  # fmt: skip
        assert cli.returncode == 2 and "twin view --stop" in cli.stderr, cli.stderr

        # Foxglove on an address other than loopback is refused, with the reason and the fix.
        with pytest.raises(RequestError, match="is not loopback.*127.0.0.1"):
            client.request("POST", "/foxglove", body={"host": "0.0.0.0", "port": 0})


TOKEN_SERVER = textwrap.dedent(
    """
    import sys
    from twin_cli.view.host import WebHost
    from twin_cli.world import World, WorldSettings

    world = World(WorldSettings())
    host = WebHost(lambda: world, host="127.0.0.2", port=int(sys.argv[1]), token="s3cret")
    print(host.start().url, flush=True)
    sys.stdin.read()
    host.close()
    """
)


def test_a_viewer_with_a_token_answers_its_own_address_only_with_the_token(tmp_path):
    """A viewer bound to a named address (127.0.0.2: loopback, but not `localhost`) with a
    token, as off loopback: its URL carries the token, the first page sets it as a cookie, and
    the page's own requests and WebSockets then pass with that cookie."""
    port = free_port("127.0.0.2")
    proc = subprocess.Popen(
        [sys.executable, "-c", TOKEN_SERVER, str(port)],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        url = proc.stdout.readline().strip()
        assert url == f"http://127.0.0.2:{port}/?token=s3cret", url
        own = f"127.0.0.2:{port}"
        assert get("127.0.0.2", port, "/", Host=own)[0] == 403, "served without the token"
        assert get("127.0.0.2", port, "/?token=s3cret", Host=f"localhost:{port}")[0] == 403
        status, cookie, _ = get("127.0.0.2", port, "/?token=s3cret", Host=own)
        assert status == 200 and cookie is not None and "HttpOnly" in cookie, cookie
        jar = cookie.split(";")[0]
        assert get("127.0.0.2", port, "/model", Host=own, Cookie=jar)[0] == 200
        wrong = jar.replace("s3cret", "guess")
        assert get("127.0.0.2", port, "/model", Host=own, Cookie=wrong)[0] == 403
        page = f"http://{own}"
        opened = handshake("127.0.0.2", port, "/state?sid=a", host=own, origin=page, Cookie=jar)
        assert opened == 101, "the page's own WebSocket with its cookie was refused"
        assert handshake("127.0.0.2", port, "/state?sid=b", host=own, origin=page) == 403
    finally:
        proc.communicate(timeout=30)


def request(path: str, **headers: str) -> Request:
    return Request(path, Headers(headers))


def test_a_wildcard_viewer_takes_any_address_of_the_machine_but_never_a_foreign_name():
    guard = ViewGuard("0.0.0.0", 8080, token="t")
    assert guard.refusal(request("/?token=t", Host="192.168.1.5:8080")) is None
    assert guard.refusal(request("/", Host="192.168.1.5:8080", Authorization="Bearer t")) is None
    assert "token" in guard.refusal(request("/", Host="192.168.1.5:8080"))
    assert "Host" in guard.refusal(request("/?token=t", Host="evil.example:8080"))
    assert "Host" in guard.refusal(request("/?token=t", Host="192.168.1.5:9999"))
    assert "Origin" in guard.refusal(request("/?token=t", Host="10.0.0.1:8080", Origin="null"))


def test_the_view_reply_says_a_public_viewer_needs_its_token_and_the_url_carries_it():
    from twin_cli.view.host import ViewAddress
    from twin_cli.view.look import PageLook
    from twin_cli.view.service import ViewService

    class Running:
        address = ViewAddress("0.0.0.0", 8080, "abc")
        syncs = 0
        look = PageLook()

    service = ViewService(lambda: None, lambda: "abc")
    service.host = Running()  # type: ignore[assignment]
    reply = service.status()
    assert reply["token_required"] and reply["token"] == "abc"
    assert reply["url"] == "http://0.0.0.0:8080/?token=abc"
    assert "needs its token" in reply["warning"]


def test_foxglove_on_an_address_other_than_loopback_is_refused_before_binding():
    from twin_cli.record.foxglove import LiveStream

    with pytest.raises(RequestError, match="Foxglove host 0.0.0.0: is not loopback.*ssh -L"):
        LiveStream(0, "0.0.0.0")
