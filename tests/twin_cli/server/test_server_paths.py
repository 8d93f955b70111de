"""A real server reads only regular files of bounded size, and takes only absolute paths.

`load` of `/dev/zero` once read until the kernel killed the server; a FIFO held the request
forever; a relative path to `save` resolved against the server's working folder (a save to
`../../../etc/passwd` replaced the machine's user list). Oracles: the CLI exits 2 within 5 s
naming the file, the API answers 422 for a relative path, and the world is unchanged after.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest
from models import block

from twin_cli.errors import WorldFileError
from twin_cli.server.client import Client

WORLD = "paths"
REPLY_S = 5.0  # [s] a refused read answers within this


@pytest.fixture(scope="module")
def server(tmp_path_factory, serve_world):
    with serve_world(tmp_path_factory.mktemp("rt"), WORLD) as served:
        client, _ = served
        box = tmp_path_factory.mktemp("robots") / "box.urdf"
        box.write_text(block(size=0.2, name="box"))
        client.spawn(str(box), name="box")
        yield served


def _twin(client: Client, *args: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "TWIN_RUNTIME_DIR": str(client.paths.directory)}
    return subprocess.run(
        [sys.executable, "-m", "twin_cli.cli.app", *args, "--world", WORLD],
        capture_output=True,
        text=True,
        env=env,
        timeout=60,
    )


def _sparse(path: Path, size: int) -> Path:
    with path.open("wb") as stream:
        stream.truncate(size)
    return path


@pytest.mark.parametrize("kind", ["dev_zero", "fifo", "sparse_2GB", "directory"])
def test_load_of_a_file_twin_does_not_read_is_exit_2_fast(server, tmp_path, kind):
    client, _ = server
    target = {
        "dev_zero": lambda: Path("/dev/zero"),
        "fifo": lambda: (os.mkfifo(tmp_path / "pipe"), tmp_path / "pipe")[1],
        "sparse_2GB": lambda: _sparse(tmp_path / "huge.json", 2 * 1024**3),
        "directory": lambda: tmp_path,
    }[kind]()
    start = time.monotonic()
    done = _twin(client, "load", str(target))
    elapsed = time.monotonic() - start
    assert done.returncode == 2, done.stdout + done.stderr
    assert str(target) in done.stderr and "Traceback" not in done.stderr, done.stderr
    wanted = "larger than 64 MiB" if kind == "sparse_2GB" else "not a regular file"
    assert wanted in done.stderr, done.stderr
    assert elapsed < REPLY_S + 10.0, f"{elapsed:.1f} s"  # a CLI start is part of it
    assert [e["name"] for e in client.entities()] == ["box"], "the world is unchanged"


def test_the_server_refuses_a_file_over_the_cap_in_process(server, tmp_path):
    client, _ = server
    huge = _sparse(tmp_path / "big.sdf", 65 * 1024**2)
    start = time.monotonic()
    with pytest.raises(Exception, match="larger than 64 MiB"):
        client.load(huge)
    assert time.monotonic() - start < REPLY_S


@pytest.mark.parametrize("route", ["/save", "/load", "/record", "/snapshot"])
@pytest.mark.parametrize("path", ["../../../etc/passwd", "relative.json", "with\x00nul"])
def test_the_api_takes_only_absolute_paths(server, route, path):
    client, _ = server
    reply = client._http.request("POST", route, json={"path": path})
    assert reply.status_code == 422, (route, path, reply.status_code, reply.text)
    assert "path" in reply.text


@pytest.mark.parametrize("field", ["source", "base_dir", "package_paths"])
@pytest.mark.parametrize("path", ["../robot.urdf", "robot.urdf", "/a\x00b"])
def test_a_spawn_takes_only_absolute_paths(server, field, path):
    """A spawn's file, text folder and packages are paths on the server host, which the client
    resolves: a relative one would be looked up in the server's own folder."""
    client, _ = server
    value = {"pkg": path} if field == "package_paths" else path
    body = {"xml": "<robot name='r'/>", field: value} if field != "source" else {field: value}
    names = lambda: [e["name"] for e in client._http.request("GET", "/entities").json()]  # noqa: E731
    before = names()
    reply = client._http.request("POST", "/entities", json=body)
    assert reply.status_code == 422, (field, path, reply.status_code, reply.text)
    assert field in reply.text and names() == before


def test_the_cli_saves_in_the_clients_folder(server, tmp_path):
    client, _ = server
    done = subprocess.run(
        [sys.executable, "-m", "twin_cli.cli.app", "save", "here.json", "--world", WORLD],
        capture_output=True,
        text=True,
        env={**os.environ, "TWIN_RUNTIME_DIR": str(client.paths.directory)},
        cwd=tmp_path,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "here.json").is_file()


def test_load_in_process_names_a_device(tmp_path):
    from twin_cli.world import savefile

    with pytest.raises(WorldFileError, match="not a regular file \\(a character device\\)"):
        savefile.load("/dev/zero")


def test_save_replaces_a_twin_save_and_an_empty_file_but_not_someone_elses(server, tmp_path):
    client, _ = server
    theirs = tmp_path / "notes.txt"
    theirs.write_text("my notes")
    refused = _twin_in(client, tmp_path, "save", "notes.txt")
    assert refused.returncode == 2, refused.stderr
    assert "notes.txt: exists and is not a file twin wrote" in refused.stderr, refused.stderr
    assert "--force" in refused.stderr and theirs.read_text() == "my notes"
    assert _twin_in(client, tmp_path, "save", "notes.txt", "--force").returncode == 0
    assert json.loads(theirs.read_text())["format"] == "twin-world"
    assert _twin_in(client, tmp_path, "save", "notes.txt").returncode == 0, "a save over a save"
    (tmp_path / "empty.json").write_text("")
    assert _twin_in(client, tmp_path, "save", "empty.json").returncode == 0, "nothing to lose"


def test_a_snapshot_does_not_replace_someone_elses_picture(server, tmp_path):
    client, _ = server
    theirs = tmp_path / "holiday.png"
    theirs.write_bytes(_png_without_software())
    reply = client._http.request("POST", "/snapshot", json={"path": str(theirs)})
    assert reply.status_code == 400 and "not a file twin wrote" in reply.text, reply.text
    assert theirs.read_bytes() == _png_without_software()


def test_twins_pictures_say_who_wrote_them():
    import numpy as np

    from twin_cli.view.offscreen import is_twin_png, png_bytes

    assert is_twin_png(png_bytes(np.zeros((8, 8, 3), dtype=np.uint8))[:4096])
    assert not is_twin_png(_png_without_software())


def _png_without_software() -> bytes:
    import io

    import numpy as np
    from matplotlib import image

    buffer = io.BytesIO()
    image.imsave(buffer, np.ones((8, 8, 3)), format="png", metadata={"Software": None})
    return buffer.getvalue()


def _twin_in(client: Client, folder: Path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "twin_cli.cli.app", *args, "--world", WORLD],
        capture_output=True,
        text=True,
        env={**os.environ, "TWIN_RUNTIME_DIR": str(client.paths.directory)},
        cwd=folder,
        timeout=60,
    )
