"""One friendly name rule in the CLI and the API; `push --json` prints what was applied."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest
from models import block

from twin_cli.names import name_message, name_problem


@pytest.mark.parametrize("bad", ["", "a/b", " a", "a ", "tab\there", "x" * 201, "bell\x07"])
def test_bad_names_get_the_rule_with_an_example(bad):
    assert name_problem(bad) is not None, f"{bad!r} accepted"
    message = name_message(bad)
    assert "without '/'" in message and "robot_1" in message, message


@pytest.mark.parametrize("good", ["robot_1", "a.b-c", "ü", "Heightmap Bowl", "x" * 200])
def test_good_names_pass(good):
    assert name_problem(good) is None


def _twin(env, *args):
    return subprocess.run(
        [sys.executable, "-m", "twin_cli.cli.app", *args],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )


def test_cli_and_api_give_the_same_friendly_name_message_and_push_json(tmp_path):
    env = {**os.environ, "TWIN_RUNTIME_DIR": str(tmp_path / "rt"), "TWIN_AUTOSAVE": "0"}
    box = tmp_path / "box.urdf"
    box.write_text(block(size=0.2, name="box"))
    cli = _twin(env, "spawn", str(box), "--name", "a/b")
    assert cli.returncode == 2, cli.stderr
    assert name_message("a/b") in cli.stderr and "Traceback" not in cli.stderr, cli.stderr
    assert not (tmp_path / "rt" / "default.pid").exists(), "a refused name started a world"
    try:
        assert _twin(env, "spawn", str(box), "--name", "box", "-z", "1").returncode == 0
        from twin_cli.errors import RequestError
        from twin_cli.server.client import Client

        os.environ["TWIN_RUNTIME_DIR"] = env["TWIN_RUNTIME_DIR"]
        with Client("default") as client, pytest.raises(RequestError) as refused:
            client.request("POST", "/entities", body={"source": str(box), "name": "a/b"})
        assert name_message("a/b") in str(refused.value), str(refused.value)
        assert "pattern" not in str(refused.value), f"a raw pydantic message: {refused.value}"
        pushed = _twin(env, "push", "box", "--force", "0", "0", "5", "--json")
        assert pushed.returncode == 0, pushed.stderr
        reply = json.loads(pushed.stdout)
        assert reply["pushed"] == "box" and reply["force"] == [0.0, 0.0, 5.0], reply
        assert reply["duration"] == pytest.approx(0.1), reply
    finally:
        os.environ.pop("TWIN_RUNTIME_DIR", None)
        _twin(env, "stop")
