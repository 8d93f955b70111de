"""The served world behind every route: held so that `/load` can swap it while requests arrive."""

from __future__ import annotations

import threading
from typing import Annotated, Any

from fastapi import Depends, Request


class WorldHolder:
    """The served world; `load` replaces it under a lock while requests keep arriving."""

    def __init__(self, world: Any) -> None:
        self.world = world
        self.swap_lock = threading.Lock()

    def replace(self, new_world: Any) -> None:
        """Stop the old world's loop and start the new one's."""
        with self.swap_lock:
            old, self.world = self.world, new_world
            old.stop()
            new_world.start()


def current_world(request: Request) -> Any:
    return request.app.state.holder.world


WorldDep = Annotated[Any, Depends(current_world)]
