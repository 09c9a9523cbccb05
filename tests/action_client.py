"""rclpy's ``ActionClient`` without its request/response race (ros2/rclpy#1123).

rclpy's client sends a goal, cancel or result request and only then files its sequence number;
the executor, on another thread, may take the server's response in between and drop it
("Ignoring unexpected goal response. There may be more than one action server ..."), and the
request's future never completes. mobil's servers answer within a millisecond, so on a loaded
machine this happens now and then: a follow_path goal answered 3 s late (the caller's retry)
stretched the navigator stand-in's once-a-second re-planning to a path every 3 simulated s.

rclpy fixed it upstream (ros2/rclpy#1308) with a lock held while a request is sent and filed,
which the executor takes to take responses; the Jazzy wheels used here (rclpy 7.1.6) have no such
lock. This subclass adds it the same way, so a response can only be taken once its request is
filed. Tests use it wherever they would use ``rclpy.action.ActionClient``.
"""

from __future__ import annotations

import threading
from typing import Any

from rclpy.action import ActionClient as _RclpyActionClient


class ActionClient(_RclpyActionClient):
    """``rclpy.action.ActionClient`` with requests filed before their responses can be taken."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        # No callback runs while it is held (the executor calls them after take_data returns).
        self._request_lock = threading.Lock()
        super().__init__(*args, **kwargs)

    def take_data(self) -> Any:
        with self._request_lock:
            return super().take_data()

    def send_goal_async(self, goal: Any, feedback_callback: Any = None, goal_uuid: Any = None) -> Any:
        with self._request_lock:
            return super().send_goal_async(goal, feedback_callback, goal_uuid)

    def _cancel_goal_async(self, goal_handle: Any) -> Any:
        with self._request_lock:
            return super()._cancel_goal_async(goal_handle)

    def _get_result_async(self, goal_handle: Any) -> Any:
        with self._request_lock:
            return super()._get_result_async(goal_handle)
