"""Propeller thrust from the command and from the hub's depth (dukw_model.propeller)."""
import numpy as np
import pytest

from dukw_common.vehicle import Vehicle
from dukw_model.propeller import prop_thrust_n, propeller_thrust_factor

DRIVETRAIN = Vehicle.load().drivetrain


def test_thrust_is_linear_in_the_command_and_weaker_in_reverse():
    full = DRIVETRAIN.max_prop_thrust_n
    assert prop_thrust_n(100.0, DRIVETRAIN) == pytest.approx(full)
    assert prop_thrust_n(50.0, DRIVETRAIN) == pytest.approx(full / 2)
    assert prop_thrust_n(0.0, DRIVETRAIN) == 0.0
    assert prop_thrust_n(-100.0, DRIVETRAIN) == pytest.approx(
        -full * DRIVETRAIN.prop_reverse_thrust_ratio)


def test_thrust_factor_follows_the_propeller_disc_in_solid_water():
    assert propeller_thrust_factor(0.40, 0.25, 0.05) == 1.0
    assert propeller_thrust_factor(0.05, 0.25, 0.05) == pytest.approx(0.5)
    assert propeller_thrust_factor(-0.10, 0.25, 0.05) == 0.0
    shares = [propeller_thrust_factor(d, 0.25, 0.05) for d in np.linspace(-0.07, 0.17, 25)]
    assert np.all(np.diff(shares) > 0.0)
