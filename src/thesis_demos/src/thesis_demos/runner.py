"""Runs the demonstrations one after another against a live stack (its ROS side: thesis_demos.stack_client;
the sixth demonstration's flow: thesis_demos.teach_client)."""

from __future__ import annotations

import time

from compliant_control_msgs.srv import PushEEFRequest

from thesis_demos.analysis import Recording
from thesis_demos.scenarios import Scenario
from thesis_demos.stack_client import Names, StackClient
from thesis_demos.teach_client import TeachFlow

__all__ = ["DemoRunner", "Names"]


class DemoRunner(StackClient):
    """Connects to the stack once, then runs scenarios one after another."""

    def run(self, scenario: Scenario, sensor_frame: str) -> Recording:
        """Brings the arm to its start pose, sets the scenario's laws, pushes, and records until done (teach
        and replay: its own flow, thesis_demos.teach_client)."""
        if scenario.teach is not None:
            return TeachFlow(self, self.names.teach).run(scenario, sensor_frame)
        baseline_t = self.prepare(sensor_frame)
        self.send(scenario, scenario.laws)
        t0 = self.now()
        pushes = sorted(scenario.pushes, key=lambda p: p.start)
        end_time = None
        follow_up, follow_up_time, settled_since = scenario.follow_up, None, None
        while not self.shutting_down():
            now = self.now() - t0
            if follow_up is not None and follow_up_time is None:
                # Sent once the force has stayed near its target for follow_up.hold (pressing on the block).
                force = self.force(follow_up.axis)
                if force is not None and abs(force - follow_up.target) <= follow_up.tolerance:
                    settled_since = now if settled_since is None else settled_since
                    if now - settled_since >= follow_up.hold:
                        self.send(scenario, follow_up.laws)
                        follow_up_time = self.now() - t0
                else:
                    settled_since = None
            while pushes and now >= pushes[0].start:
                push = pushes.pop(0)
                req = PushEEFRequest(duration=push.duration)
                req.wrench.force.x, req.wrench.force.y, req.wrench.force.z = push.force
                self.push(req)
            active, _ = self.move_state()
            if end_time is None and not active and now > 0.2:
                end_time = now
            if now >= scenario.duration:
                break
            if scenario.end_when_move_ends and end_time is not None and now >= end_time + scenario.settle:
                break
            time.sleep(0.005)
        _, ends = self.move_state()
        self.stop()
        if end_time is not None:
            end_time = self.ended_at(end_time + t0) - t0
        recording = self.recording(t0, baseline_t, ends, end_time)
        recording.follow_up_time = follow_up_time
        return recording
