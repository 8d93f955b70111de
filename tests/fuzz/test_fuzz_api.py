"""The HTTP API fuzzed from its own OpenAPI schema (Schemathesis) against a live `twin serve`.

Properties, for every operation: no 5xx; the status code is one the schema documents; the body
matches the schema of that status; afterwards the world still steps. `make test` runs a few
derandomised cases per operation; `make fuzz` many more (TWIN_FUZZ_EXAMPLES).
Operations that write files or open listeners (/save, /record, /foxglove, /view, /snapshot,
/ros) are fuzzed with every path confined to the server's temporary directory (the fuzzed name
is kept, its '/' replaced), every host set to 127.0.0.1 and the ROS 2 bridge's interface and
variables left out (loopback only): as root on the test machine they could otherwise write
anywhere, listen on every interface or send to the network. /shutdown is called last, once, and
must end the server cleanly. `/step` counts are capped at 1,000 and snapshot sizes at 640 px so
one case cannot hold the world for minutes (both legitimate, slow requests), and an echo stream
at one message.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time

import pytest

schemathesis = pytest.importorskip("schemathesis")
from hypothesis import HealthCheck, settings  # noqa: E402
from models import block  # noqa: E402
from schemathesis import checks  # noqa: E402

from twin_cli.server import runtime  # noqa: E402
from twin_cli.server.client import Client  # noqa: E402

EXAMPLES = int(os.environ.get("TWIN_FUZZ_API_EXAMPLES", 5))  # per operation
CONFINED = ("/save", "/record", "/foxglove", "/view", "/snapshot", "/ros")
MAX_STEPS = 1000
MAX_PIXELS = 640  # [px] per snapshot side


@pytest.fixture(scope="module")
def live(tmp_path_factory):
    """A served world over TCP with its token, holding one box, in a private runtime dir.

    The server's working directory is a temporary one: relative paths the fuzzer invents land
    there.
    """
    rt = tmp_path_factory.mktemp("rt")
    box = rt / "box.urdf"
    box.write_text(block(size=0.2, name="box"))
    env = {**os.environ, runtime.RUNTIME_ENV: str(rt)}
    cmd = [sys.executable, "-m", "twin_cli.cli.app", "serve", "--world", "apifuzz"]
    with open(rt / "serve.out", "wb") as out:
        proc = subprocess.Popen(
            [*cmd, "--tcp", "127.0.0.1:0", "--no-autosave"],
            stdout=out,
            stderr=out,
            env=env,
            cwd=rt,
        )
    os.environ[runtime.RUNTIME_ENV] = str(rt)
    client = Client("apifuzz")
    try:
        runtime.wait_until(client.paths, client.alive, proc, 60.0)
        client.spawn(box, name="box", pose={"z": 0.5})
        address = (rt / "apifuzz.tcp").read_text().strip()
        token = (rt / "apifuzz.token").read_text().strip()
        yield {
            "client": client,
            "proc": proc,
            "url": f"http://{address}",
            "token": token,
            "root": rt,
        }
    finally:
        proc.terminate()
        proc.wait(timeout=30)
        del os.environ[runtime.RUNTIME_ENV]


def _schema_document() -> dict:
    """The API's OpenAPI document, as the server builds it (checked against the live one below)."""
    from twin_cli.server.app import create_app
    from twin_cli.world import World

    return create_app(World(), world_name="apifuzz").openapi()


DOCUMENT = _schema_document()
OPENAPI = schemathesis.openapi.from_dict(DOCUMENT)
schema = OPENAPI.exclude(path_regex="|".join(("/shutdown", *CONFINED)))
confined = OPENAPI.include(path_regex="|".join(f"^{p}$" for p in CONFINED))
CHECKS = [
    checks.not_a_server_error,
    checks.status_code_conformance,
    checks.content_type_conformance,
    checks.response_schema_conformance,
]


def test_live_server_serves_the_fuzzed_schema(live):
    import json
    import urllib.request

    request = urllib.request.Request(
        f"{live['url']}/openapi.json", headers={"Authorization": f"Bearer {live['token']}"}
    )
    with urllib.request.urlopen(request, timeout=30) as reply:
        served = json.loads(reply.read())
    assert served == json.loads(json.dumps(DOCUMENT)), "live /openapi.json differs"


@schema.parametrize()
@settings(
    max_examples=EXAMPLES,
    deadline=None,
    derandomize=True,
    suppress_health_check=list(HealthCheck),
)
def test_api_answers_within_its_schema_and_never_5xx(case, live):
    if case.path == "/step" and isinstance(case.body, dict) and isinstance(case.body.get("n"), int):
        case.body["n"] = min(case.body["n"], MAX_STEPS)
    if case.path == "/topics/echo":  # a stream ends after `count` messages (0: never)
        case.query = {**(case.query or {}), "count": 1}
    _call(case, live)


def _call(case, live) -> None:  # noqa: ANN001
    case.call_and_validate(
        base_url=live["url"],
        headers={"Authorization": f"Bearer {live['token']}"},
        checks=CHECKS,
        timeout=120,
    )


def _confine(body: dict, root) -> None:  # noqa: ANN001
    """Paths into `root` (the fuzzed name kept, '/' and NUL replaced), hosts to loopback."""
    if isinstance(body.get("path"), str) and body["path"]:
        name = body["path"].replace("/", "_").replace("\x00", "_")
        body["path"] = str(root / "confined" / name)
    if "host" in body:
        body["host"] = "127.0.0.1"
    # the ROS 2 bridge stays on loopback: no interface, none of ROS's widening variables
    body.pop("interface", None)
    body.pop("environment", None)
    for side in ("width", "height"):
        if isinstance(body.get(side), int):
            body[side] = min(body[side], MAX_PIXELS)


@confined.parametrize()
@settings(
    max_examples=EXAMPLES,
    deadline=None,
    derandomize=True,
    suppress_health_check=list(HealthCheck),
)
def test_file_and_listener_operations_within_a_sandbox(case, live):
    root = live["root"]
    (root / "confined").mkdir(exist_ok=True)
    if isinstance(case.body, dict):
        _confine(case.body, root)
    _call(case, live)


def test_world_still_steps_after_the_fuzz(live):
    """Run last in this module (pytest keeps file order): the server lives and the world steps."""
    client: Client = live["client"]
    assert live["proc"].poll() is None, "the server died during the API fuzz"
    physics = client.physics()  # what the fuzz left (a legitimate, tiny rate steps slowly)
    client.set_physics(rate=1000.0, timestep=0.001)
    client.resume()
    before = client.stats()["sim_time"]
    time.sleep(0.5)
    after = client.stats()["sim_time"]
    assert after > before, f"sim time stuck at {before} s after the fuzz left {physics}"


def test_shutdown_answers_and_ends_the_server(live):
    """Last: /shutdown answers within its schema and the server exits with status 0."""
    ops = OPENAPI.include(path_regex="^/shutdown$")
    operation = next(iter(ops.get_all_operations())).ok()
    _call(operation.Case(), live)
    assert live["proc"].wait(timeout=30) == 0, "the server did not end cleanly"
