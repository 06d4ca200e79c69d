import pytest
from compliant_common.tf_prefix import TfPrefix


def test_a_prefix_goes_on_the_robots_frames_and_comes_off_received_ones():
    left = TfPrefix("/left/")
    assert left.prefix == "left" and bool(left)
    assert left.add("base_link") == "left/base_link"
    assert left.add("/tool0") == "left/tool0"
    assert left.add("left/tool0") == "left/tool0"  # once only
    assert left.add("") == ""  # a message's "no frame" stays so
    assert left.bare("left/base_link") == "base_link"
    assert left.bare("/left/base_link") == "base_link"
    assert left.bare("right/base_link") == "right/base_link"  # another robot's frame keeps its name
    assert left.bare("base_link") == "base_link"
    assert left.bare("leftover") == "leftover"  # a name that only starts with the same letters


def test_no_prefix_changes_nothing_but_a_leading_slash():
    none = TfPrefix()
    assert not none and none.prefix == ""
    assert none.add("base_link") == "base_link" and none.add("/base_link") == "base_link"
    assert none.bare("/left/base_link") == "left/base_link"


def test_a_prefix_with_a_space_is_refused():
    with pytest.raises(ValueError, match="no spaces"):
        TfPrefix("left arm")
