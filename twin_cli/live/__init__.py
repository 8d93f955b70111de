"""A live look inside a running world: its topics, one topic's messages, one entity's parts.

A consumer of the world, like the recorder (whose topic names, message types and tf frames it
reuses, so what is shown live is what a recording holds): `catalogue` lists the topics a world
offers with their types and rates (`twin topics`), `echo` follows one topic's messages as the
world makes them (`twin topics echo`), `model` describes one entity with world poses (`twin
model`, `gz model -m`). The world is only read: copies under its lock, work outside it.
"""

from __future__ import annotations

from twin_cli.live.catalogue import LiveTopic, find_topic, live_topics
from twin_cli.live.echo import Echo
from twin_cli.live.model import describe

__all__ = ["Echo", "LiveTopic", "describe", "find_topic", "live_topics"]
