"""The HTTP API fuzzed from its own OpenAPI schema (Schemathesis) against a live `twin serve`.

Properties, for every operation: no 5xx; the status code is one the schema documents; the body
matches the schema of that status; afterwards the world still steps. `make test` runs a few
derandomised cases per operation; `make fuzz` many more (TWIN_FUZZ_EXAMPLES).
Left out: operations that end the server (/shutdown), or write files or open listeners at
paths and addresses the fuzzer invents (/save, /record, /foxglove, /view, /snapshot): as root on
the test machine they could write anywhere. `/step` counts are capped at 1,000 so one case
cannot hold the world for minutes (the schema allows 10^7: a legitimate, slow request).
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
SKIPPED = ("/shutdown", "/save", "/record", "/foxglove", "/view", "/snapshot")
MAX_STEPS = 1000


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
        yield {"client": client, "proc": proc, "url": f"http://{address}", "token": token}
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
schema = schemathesis.openapi.from_dict(DOCUMENT).exclude(path_regex="|".join(SKIPPED))


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
    case.call_and_validate(
        base_url=live["url"],
        headers={"Authorization": f"Bearer {live['token']}"},
        checks=[
            checks.not_a_server_error,
            checks.status_code_conformance,
            checks.content_type_conformance,
            checks.response_schema_conformance,
        ],
        timeout=120,
    )


def test_world_still_steps_after_the_fuzz(live):
    """Run last in this module (pytest keeps file order): the server lives and the world steps."""
    client: Client = live["client"]
    assert live["proc"].poll() is None, "the server died during the API fuzz"
    client.resume()
    before = client.stats()["sim_time"]
    time.sleep(0.5)
    after = client.stats()["sim_time"]
    assert after > before, f"sim time stuck at {before} s after the fuzz"
