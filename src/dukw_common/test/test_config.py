"""Parameter-file loading: the shared block, node blocks, and clear errors on bad input."""
import math

import pytest

from dukw_common import config
from dukw_common.config import ConfigError
from dukw_common.vehicle import Vehicle, soil_params


def test_stack_config_builds_the_vehicle_with_the_papers_numbers():
    vehicle = Vehicle.load()
    assert vehicle.body.displacement_n == 2894.0
    assert vehicle.drivetrain.track_force_gain_n_per_a == 8.16
    assert vehicle.drivetrain.continuous_current_limit_a == 35.0
    assert vehicle.drivetrain.port_bias_pct == 4.0
    assert vehicle.body.mass_kg == pytest.approx(295, abs=1)


def test_node_block_overlays_the_shared_block(tmp_path):
    path = tmp_path / 'p.yaml'
    path.write_text('/**:\n  ros__parameters:\n    a: {b: 1.0, c: 2}\n'
                    'n1:\n  ros__parameters:\n    a: {b: 5.0}\n    rate_hz: 10.0\n')
    assert config.node_params('n1', path) == {'a.b': 5.0, 'a.c': 2, 'rate_hz': 10.0}
    assert config.node_params('other', path) == {'a.b': 1.0, 'a.c': 2}


@pytest.mark.parametrize('text,message', [
    ('n: [unclosed', 'not valid YAML'),
    ('- just\n- a list\n', 'mapping of node names'),
    ('n:\n  params: {}\n', 'ros__parameters'),
])
def test_malformed_files_raise_config_error(tmp_path, text, message):
    path = tmp_path / 'bad.yaml'
    path.write_text(text)
    with pytest.raises(ConfigError, match=message):
        config.load_file(path)


def test_missing_file_names_the_path(tmp_path):
    with pytest.raises(ConfigError, match='nope.yaml'):
        config.load_file(tmp_path / 'nope.yaml')


def test_require_rejects_missing_nan_and_wrong_types():
    with pytest.raises(ConfigError, match="'x'"):
        config.require({}, 'x')
    with pytest.raises(ConfigError, match='finite'):
        config.require({'x': math.nan}, 'x')
    with pytest.raises(ConfigError):
        config.require({'x': 'fast'}, 'x')
    with pytest.raises(ConfigError):
        config.require({'x': True}, 'x')
    assert config.require({'x': 3}, 'x') == 3.0


def test_soil_presets_and_unknown_preset():
    params = config.shared_params()
    dry = soil_params(params, 'dry_sand')
    assert dry.cohesion_pa == 1040.0
    assert dry.friction_angle_rad == pytest.approx(math.radians(28), abs=1e-3)
    with pytest.raises(ConfigError, match='unknown soil preset'):
        soil_params(params, 'moon_dust')


def test_missing_vehicle_parameter_is_named():
    params = config.shared_params()
    del params['vehicle.displacement_n']
    with pytest.raises(ConfigError, match='vehicle.displacement_n'):
        Vehicle.from_params(params)
