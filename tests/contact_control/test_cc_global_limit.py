"""The global limits' trip counts wrenches over a limit in a row; alternating spikes never trip it."""

from contact_control.global_limit import GlobalLimit


def test_only_samples_in_a_row_trip():
    limit = GlobalLimit(3)
    assert [limit.spike(over, latched=False) for over in (True, True, False, True, True)] == [True] * 2 + [
        False, True, True]
    assert not limit.spike(True, latched=False)  # the third in a row: the caller trips
    assert not GlobalLimit(3).spike(True, latched=True)  # latched already: not ridden out


def test_the_message_names_the_wrench_and_the_limits():
    text = GlobalLimit.message([30.0, 40.0, 0.0, 0.0, 0.0, 2.0], 25.0, 3.0)
    assert "|F| 50.0 N of 25.0 N" in text and "|T| 2.0 Nm of 3.0 Nm" in text and "reset" in text
    assert "nan" in GlobalLimit.message(None, 25.0, 3.0)
