"""A recording cut short by a full disk ends `twin record` at once with exit 2 and the cause.

Run as a user would, in a private mount namespace (`unshare -m`, so nothing is mounted on the
machine): a 64 KiB tmpfs is the bag's folder; the world serves a box; `twin record --duration 600`
must not wait out its ten minutes on a bag that stopped at the first full write.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest
from models import block

SCRIPT = """
set -u
mount -t tmpfs -o size=64k tmpfs "$BAGS" || exit 97
$TWIN spawn "$URDF" --world full >/dev/null 2>&1 || exit 98
$TWIN record "$BAGS/out.mcap" --world full --duration 600
rc=$?
$TWIN stop --world full >/dev/null 2>&1
exit $rc
"""


def test_a_full_disk_ends_twin_record_with_exit_2_naming_the_bag(tmp_path: Path) -> None:
    if shutil.which("unshare") is None or os.geteuid() != 0:
        pytest.skip("needs root and unshare(1) to mount a small tmpfs")
    (tmp_path / "bags").mkdir()
    (tmp_path / "box.urdf").write_text(block(size=0.2, name="box"))
    env = {
        **os.environ,
        "TWIN_RUNTIME_DIR": str(tmp_path / "rt"),
        "BAGS": str(tmp_path / "bags"),
        "URDF": str(tmp_path / "box.urdf"),
        "TWIN": f"{sys.executable} -m twin_cli.cli.app",
    }
    start = time.monotonic()
    done = subprocess.run(
        ["unshare", "-m", "sh", "-c", SCRIPT], capture_output=True, text=True, env=env, timeout=280
    )
    elapsed = time.monotonic() - start
    if done.returncode in (97, 98):
        pytest.skip(f"this machine cannot set the test up: {done.stderr.strip()[-300:]}")
    bag = tmp_path / "bags" / "out.mcap"
    assert done.returncode == 2, done.stdout + done.stderr
    assert f"{bag}: recording stopped early" in done.stderr, done.stderr
    assert "No space left on device" in done.stderr, done.stderr
    # The CLI's start, a world's start and the spawn are in it (slow on a busy runner); the bag
    # fills in seconds, and before, the command waited out the whole duration.
    assert elapsed < 150.0, f"twin record waited {elapsed:.0f} s on a stopped recording"
