"""IMC gains from identified model files, and the controller using them per medium."""
import dataclasses

import numpy as np
import pytest
import yaml

from dukw_common.config import node_params
from dukw_control import controller
from dukw_control.model_gains import (ModelGainError, load_model, model_channels,
                                      settings_with_model_gains)
from dukw_control.modes import Mode, ModeDecision

DT_S = 0.01


def _write_model(path, medium, surge_gain, surge_tau_s, yaw_gain, yaw_tau_s, y_offset=None):
    """Two decoupled first-order channels: u from the common, r from the differential."""
    a_u, a_r = float(np.exp(-DT_S / surge_tau_s)), float(np.exp(-DT_S / yaw_tau_s))
    data = {
        'medium': medium, 'dt_s': DT_S, 'inputs': ['port_cmd', 'stbd_cmd'],
        'outputs': ['u', 'v', 'r'], 'A': [[a_u, 0.0], [0.0, a_r]],
        # x1 = common-mode state, x2 = differential state (stbd - port) / 2
        'B': [[(1 - a_u) / 2, (1 - a_u) / 2], [-(1 - a_r) / 2, (1 - a_r) / 2]],
        'C': [[surge_gain, 0.0], [0.0, 0.0], [0.0, yaw_gain]],
        'D': [[0.0, 0.0]] * 3, 'u_offset': [40.0, 40.0],
        'y_offset': y_offset or [0.8, 0.0, 0.0]}
    path.write_text(yaml.safe_dump(data))
    return path


def _settings():
    return controller.settings_from_params(node_params('drive_controller_node'))


def test_channels_and_imc_gains_of_a_known_first_order_model(tmp_path):
    land = _write_model(tmp_path / 'land.yaml', 'land', 0.02, 0.5, 0.04, 0.25)
    surge, yaw = model_channels(load_model(land))
    assert surge.gain_per_pct == pytest.approx(0.02, rel=1e-6)
    assert yaw.gain_per_pct == pytest.approx(0.04, rel=1e-6)
    assert surge.tau_s == pytest.approx(0.5, abs=0.02)
    assert yaw.tau_s == pytest.approx(0.25, abs=0.02)
    base = _settings()
    tuned = settings_with_model_gains(base, [land], lambda_factor=2.0)
    # the PI sees the mixer (100 % per full-scale track speed) then the vehicle
    k_speed = 0.02 * 100.0 / base.land.full_scale_track_speed_mps
    assert tuned.speed_kp == pytest.approx(1.0 / (k_speed * 2.0), rel=0.05)
    assert tuned.speed_ki == pytest.approx(1.0 / (k_speed * 2.0 * 0.5), rel=0.05)
    k_yaw = 0.04 * 100.0 / base.land.full_scale_track_speed_mps * \
        base.land.effective_track_separation_m / 2.0
    assert tuned.yaw_kp == pytest.approx(1.0 / (k_yaw * 2.0), rel=0.05)
    assert tuned.water_gains is None          # no water model: afloat keeps the same gains
    slower = settings_with_model_gains(base, [land], lambda_factor=4.0)
    assert slower.speed_kp < tuned.speed_kp


def test_the_controller_switches_to_the_water_gains_afloat(tmp_path):
    water = _write_model(tmp_path / 'water.yaml', 'water', 0.01, 2.0, 0.002, 0.6)
    settings = settings_with_model_gains(_settings(), [water])
    assert settings.water_gains is not None
    ctrl = controller.DriveController(settings)
    ctrl.on_authority(True, 'computer', 0.0)
    ctrl.on_cmd_vel(0.8, 0.0, 0.0)
    ctrl.on_odometry(0.5, 0.0, 0.0)
    ctrl.on_mode(ModeDecision(Mode.WATER, True, 0.0, 1.0, False, 'afloat'))
    ctrl.step(0.0)
    ctrl.step(0.01)
    assert ctrl.speed_pi.kp == settings.water_gains.speed_kp != settings.speed_kp
    assert ctrl.yaw_pi.ki == settings.water_gains.yaw_ki


def test_model_gains_chosen_by_parameter_and_bad_input_refused(tmp_path):
    land = _write_model(tmp_path / 'land.yaml', 'land', 0.02, 0.5, 0.04, 0.25)
    params = dict(node_params('drive_controller_node'))
    assert params['gains.source'] == 'hand'       # hand-tuned gains stay the default
    hand = controller.settings_from_params(params)
    params.update({'gains.source': 'model', 'gains.land_model': str(land)})
    model = controller.settings_from_params(params)
    assert (model.speed_kp, model.yaw_kp) != (hand.speed_kp, hand.yaw_kp)
    with pytest.raises(ValueError, match='gains.source'):
        controller.settings_from_params({**params, 'gains.source': 'magic'})
    with pytest.raises(ValueError, match='needs gains.land_model'):
        controller.settings_from_params({**params, 'gains.land_model': ''})
    unstable = tmp_path / 'unstable.yaml'
    data = yaml.safe_load(land.read_text())
    unstable.write_text(yaml.safe_dump({**data, 'A': [[1.01, 0.0], [0.0, 0.5]]}))
    with pytest.raises(ModelGainError, match='unstable'):
        load_model(unstable)
    with pytest.raises(ModelGainError, match='not a sysid model'):
        load_model(tmp_path / 'missing.yaml')
    flipped = _write_model(tmp_path / 'flip.yaml', 'land', 0.02, 0.5, -0.04, 0.25)
    with pytest.raises(ModelGainError, match='loop gain must be positive'):
        settings_with_model_gains(hand, [flipped])
    assert dataclasses.replace(hand).speed_kp == hand.speed_kp
