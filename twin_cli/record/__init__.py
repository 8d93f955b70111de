"""Recording and streaming a running world as ROS 2 data: rosbag2 MCAP files and Foxglove.

A consumer of the world: it observes the stepping loop at its own rate through
`World.add_observer`, copies what it needs under the world's lock and encodes outside it. The
world never imports this package. Modules: `frames` (frame names, the URDF's tree, sensors'
frames), `tf_tree` (each entity's tf edges), `layout` (frames and joints per entity), `sampler`
(the copy, the kinematics), `topics` (the ROS topics and messages), `messages` (types and CDR,
rosbags), `mcap_writer` (rosbag2 MCAP files), `foxglove` (the live server), `recorder` (the
worker thread that ties them, for live sinks), `ring`, `encoder`, `bag_recording` (a bag
recording whose encoding runs in another process, fed through shared memory).
"""

from __future__ import annotations

from twin_cli.record.bag_recording import BagRecording
from twin_cli.record.foxglove import LiveStream
from twin_cli.record.mcap_writer import BagWriter
from twin_cli.record.recorder import BagSink, Recording, RecordingStatus
from twin_cli.record.topics import Message, Topic

__all__ = [
    "BagRecording",
    "BagSink",
    "BagWriter",
    "LiveStream",
    "Message",
    "Recording",
    "RecordingStatus",
    "Topic",
]
