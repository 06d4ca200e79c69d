"""What the stage says in the node's log: a missing transform is logged once when it starts and once when it
ends (it held the arm with zero twists and only ~status said why: the bench's node read zeros for weeks)."""

from __future__ import annotations

from contact_control.axes import SAFETY_NO_TF, SAFETY_OK
from contact_control.stage import ContactStage

from contact_control import load_settings

from .cc_sim import DT

IDENTITY = [[1.0, 0, 0, 0], [0, 1.0, 0, 0], [0, 0, 1.0, 0], [0, 0, 0, 1.0]]


def test_a_missing_transform_is_logged_once_and_its_return_too():
    known = {"base_link"}

    def poses(frame: str):
        if frame not in known:
            raise LookupError(f'"{frame}" passed to lookupTransform does not exist')
        return [row[:] for row in IDENTITY]

    stage = ContactStage(load_settings({"tare_on_startup": False, "eef_frame": "tool0"}), poses)
    for i in range(50):
        stage.on_wrench((0, 0, 0, 0, 0, 0), "", None, (i + 1) * DT)
    result, message = stage.status()
    assert result.safety == SAFETY_NO_TF and "tool0" in message
    warned = [text for level, text in stage.notes if "tool0" in text]
    assert len(warned) == 1 and stage.notes[0][0] == "warn" and "holding" in warned[0], stage.notes
    stage.notes.clear()
    known.add("tool0")
    for i in range(50, 60):
        stage.on_wrench((0, 0, 0, 0, 0, 0), "", None, (i + 1) * DT)
    assert [level for level, _ in stage.notes] == ["info"] and "again" in stage.notes[0][1], stage.notes
    assert stage.status()[0].safety == SAFETY_OK
