"""sysid: N4SID on a known system, on the simulator's zigzags, on a recorded bag; refusals."""
import json

import numpy as np
import pytest
import yaml

from dukw_estimation import sysid
from dukw_model import state_space
from dukw_estimation.sysid_cli import load_model, main, save_model
from dukw_estimation.sysid_io import read_run
from dukw_sim import maneuver

pytestmark = pytest.mark.timeout(120)

TRUE_A = np.diag([0.97, 0.9, 0.8])
TRUE_B = np.array([[0.02, 0.01], [0.0, 0.05], [0.03, -0.03]])
TRUE_C = np.array([[1.0, 0.5, 0.0], [0.0, 1.0, 0.3], [0.2, 0.0, 1.0]])


def _known_run(seed: int, n: int = 3000, noise: float = 0.01) -> state_space.Run:
    """The known third-order system driven by random held steps, output noise added."""
    rng = np.random.default_rng(seed)
    u = np.repeat(rng.uniform(-50.0, 50.0, size=(n // 50, 2)), 50, axis=0)
    x, y = np.zeros(3), np.empty((n, 3))
    for k in range(n):
        y[k] = TRUE_C @ x
        x = TRUE_A @ x + TRUE_B @ u[k]
    y += noise * np.std(y, axis=0) * rng.standard_normal(y.shape)
    return state_space.Run(f'known-{seed}', 'land', 0.01 * np.arange(n), u, y)


def test_known_third_order_system_poles_and_validation_fit():
    result = sysid.identify([_known_run(1)], 'land', order=3)
    found = np.sort(np.abs(result.model.poles()))
    true = np.sort(np.diag(TRUE_A))
    assert np.all(np.abs(found - true) / true < 0.05), (found, true)
    assert result.suggested_order == 3
    check = state_space.compare(result.model, _known_run(2))
    assert min(check.fit_pct.values()) >= 90.0, check.fit_pct
    assert min(check.one_step_fit_pct.values()) >= 90.0


def test_fit_is_matlab_compare_formula():
    y = np.array([[0.0, 1.0, 2.0], [2.0, 3.0, 2.0], [4.0, 5.0, 8.0]])
    assert state_space.fit_pct(y, y) == {'u': 100.0, 'v': 100.0, 'r': 100.0}
    flat = state_space.fit_pct(y, np.tile(y.mean(axis=0), (3, 1)))
    assert flat == pytest.approx({'u': 0.0, 'v': 0.0, 'r': 0.0})


@pytest.fixture(scope='module')
def zigzags(tmp_path_factory):
    """The paper's land zigzags 56/32 and 88/56 on the simulator, as maneuver CSVs."""
    folder = tmp_path_factory.mktemp('zigzag')
    out = {}
    for medium, high, low in (('land', 56, 32), ('land', 88, 56)):
        path = folder / f'{medium}_{high}_{low}.csv'
        maneuver.main(['zigzag', '--medium', medium, '--high', str(high), '--low', str(low),
                       '--lead-in', '2', '--csv', str(path)])
        out[(high, low)] = path
    return out


def _last_json(capsys) -> dict:
    return json.loads(capsys.readouterr().out.strip().splitlines()[-1])


def test_simulator_land_56_32_validates_on_88_56(zigzags, tmp_path, capsys):
    """Validated on another of the paper's pairs. Not on 100/80: its differential (16/24 with
    the port bias) sits near the skid-steer threshold where the radius grows fast (issue 13),
    which no linear model fitted at 56/32 follows (r fit ~44 %; 88/64, 100/64: 76-77 %)."""
    model_path = tmp_path / 'land.yaml'
    plots = tmp_path / 'plots'
    assert main(['identify', '--medium', 'land', '--out', str(model_path), '--plots',
                 str(plots), str(zigzags[(56, 32)])]) == 0
    text = capsys.readouterr().out
    assert 'singular values' in text and 'suggested order' in text
    summary = json.loads(text.strip().splitlines()[-1])
    assert summary['order'] == 3 and summary['medium'] == 'land'
    assert summary['fit_pct']['u'] >= 80.0 and summary['fit_pct']['r'] >= 90.0
    assert (plots / 'singular_values.png').stat().st_size > 0
    # the model's own operating point: yaw rate extrapolates, speed less so (slip)
    assert main(['validate', str(model_path), str(zigzags[(88, 56)])]) == 0
    assert _last_json(capsys)['fit_pct']['r'] >= 70.0
    # about the validation run's means (MATLAB: detrend both data sets)
    assert main(['validate', str(model_path), '--detrend', '--plots', str(plots),
                 str(zigzags[(88, 56)])]) == 0
    valid = _last_json(capsys)
    assert valid['fit_pct']['u'] >= 70.0 and valid['fit_pct']['r'] >= 70.0, valid
    assert valid['offsets'] == 'run' and len(valid['plots']) == 1
    assert main(['compare-paper', str(model_path), str(zigzags[(88, 56)])]) == 0
    paper = _last_json(capsys)
    assert len(paper['paper']['poles']) == 3
    # both agree on the sign of the turn (paper's outputs converted to REP 103)
    ours, theirs = (np.array(paper[k]['dc_gain_per_pct']) for k in ('identified', 'paper'))
    assert np.sign(ours[2, 0]) == np.sign(theirs[2, 0]) == -1.0
    assert paper['fit_pct']['r'] > paper['paper_fit_pct']['r']


def _write_bag(path, run: maneuver.ManeuverRun, medium_code: int, rate_hz: float = 50.0,
               topics=('tracks/cmd', 'odometry/filtered', 'sim/truth')):
    """A rosbag2 of the run written with the project's bag writer (truth as odometry)."""
    from dukw_bringup.bag_io import BagWriter, typestore
    store = typestore()
    t = store.types
    step = int(round(1.0 / rate_hz / 0.01))
    with BagWriter(path, store) as writer:
        for row in run.rows[::step]:
            ns = int(round(row.t_s * 1e9)) + 1
            header = t['std_msgs/msg/Header'](stamp=t['builtin_interfaces/msg/Time'](
                sec=int(row.t_s), nanosec=int((row.t_s % 1) * 1e9)), frame_id='odom')
            vec = t['geometry_msgs/msg/Vector3']
            if 'tracks/cmd' in topics:
                writer.write_message('/tracks/cmd', 'dukw_msgs/msg/DiffCommand', ns, t[
                    'dukw_msgs/msg/DiffCommand'](header=header, port_pct=row.port_cmd_pct,
                                                 stbd_pct=row.stbd_cmd_pct))
            if 'odometry/filtered' in topics:
                twist = t['geometry_msgs/msg/TwistWithCovariance'](
                    twist=t['geometry_msgs/msg/Twist'](
                        linear=vec(x=row.surge_mps, y=row.sway_mps, z=0.0),
                        angular=vec(x=0.0, y=0.0, z=row.yaw_rate_rps)),
                    covariance=np.zeros(36))
                pose = t['geometry_msgs/msg/PoseWithCovariance'](
                    pose=t['geometry_msgs/msg/Pose'](
                        position=t['geometry_msgs/msg/Point'](x=row.x_m, y=row.y_m, z=0.0),
                        orientation=t['geometry_msgs/msg/Quaternion'](x=0.0, y=0.0, z=0.0,
                                                                      w=1.0)),
                    covariance=np.zeros(36))
                writer.write_message('/odometry/filtered', 'nav_msgs/msg/Odometry', ns + 1,
                                     t['nav_msgs/msg/Odometry'](header=header,
                                                                child_frame_id='base_link',
                                                                pose=pose, twist=twist))
            if 'drive_mode' in topics:
                code = medium_code(row.t_s) if callable(medium_code) else medium_code
                writer.write_message('/drive_mode', 'dukw_msgs/msg/DriveMode', ns + 2, t[
                    'dukw_msgs/msg/DriveMode'](header=header, mode=code, automatic=True,
                                               track_weight=1.0, prop_weight=0.0,
                                               tracks_idle=False, reason=''))
    return path


@pytest.fixture(scope='module')
def land_zigzag_run():
    return maneuver.zigzag('land', 56, 32, lead_in_s=2.0)


def test_identify_from_a_recorded_bag(land_zigzag_run, tmp_path, capsys):
    bag = _write_bag(tmp_path / 'bag', land_zigzag_run, 0,
                     topics=('tracks/cmd', 'odometry/filtered', 'drive_mode'))
    model_path = tmp_path / 'm.yaml'
    assert main(['identify', '--medium', 'land', '--out', str(model_path), str(bag)]) == 0
    summary = _last_json(capsys)
    assert summary['fit_pct']['u'] >= 80.0 and summary['fit_pct']['r'] >= 90.0, summary
    model = load_model(str(model_path))
    assert model.dt_s == pytest.approx(0.01)
    # the operating point recorded: mean commands over 2 s at rest and three half-periods
    expected = [(56 * 20 + 32 * 10) / 32, (32 * 20 + 56 * 10) / 32]
    assert model.u_offset == pytest.approx(expected, abs=0.5)


def test_a_bag_of_several_media_gives_its_stretch_in_the_asked_one(land_zigzag_run, tmp_path,
                                                                   capsys):
    bag = _write_bag(tmp_path / 'mixed', land_zigzag_run, lambda t: 0 if t < 20.0 else 2,
                     topics=('tracks/cmd', 'odometry/filtered', 'drive_mode'))
    assert main(['identify', '--medium', 'land', str(bag)]) == 0
    out = capsys.readouterr().out
    assert 'mixed: 19.9 s' in out or 'mixed: 20.0 s' in out, out


def test_refusals(land_zigzag_run, zigzags, tmp_path, capsys):
    model_path = tmp_path / 'land.yaml'
    assert main(['identify', '--medium', 'land', '--out', str(model_path),
                 str(zigzags[(56, 32)])]) == 0
    capsys.readouterr()
    # too short
    short = tmp_path / 'short.csv'
    maneuver.zigzag('land', 56, 32, duration_s=2.0).write_csv(str(short))
    assert main(['identify', '--medium', 'land', str(short)]) == 2
    assert 'too short' in capsys.readouterr().err
    # no excitation: constant commands (a circle)
    circle = tmp_path / 'circle.csv'
    maneuver.circle('land', 60, 40, duration_s=10.0).write_csv(str(circle))
    assert main(['identify', '--medium', 'land', str(circle)]) == 2
    assert 'no excitation' in capsys.readouterr().err
    # mismatched media: a water run for a land model, a land model on a water run
    water = tmp_path / 'water.csv'
    maneuver.zigzag('water', 80, 0, duration_s=10.0).write_csv(str(water))
    assert main(['identify', '--medium', 'land', str(water)]) == 2
    assert 'mismatched media' in capsys.readouterr().err
    assert main(['validate', str(model_path), str(water)]) == 2
    assert 'mismatched media' in capsys.readouterr().err
    # a bag whose drive_mode says water, read as land
    wet = _write_bag(tmp_path / 'wet', land_zigzag_run, 2,
                     topics=('tracks/cmd', 'odometry/filtered', 'drive_mode'))
    assert main(['identify', '--medium', 'land', str(wet)]) == 2
    assert 'mismatched media' in capsys.readouterr().err
    # a bag without the needed topics
    bare = _write_bag(tmp_path / 'bare', land_zigzag_run, 0, topics=('tracks/cmd',))
    assert main(['identify', '--medium', 'land', str(bare)]) == 2
    assert 'odometry/filtered' in capsys.readouterr().err
    assert main(['identify', '--medium', 'land', '--truth', str(bare)]) == 2
    assert 'sim/truth' in capsys.readouterr().err
    # not a run at all; a malformed model
    assert main(['identify', '--medium', 'land', str(tmp_path / 'nothing.txt')]) == 2
    bad = tmp_path / 'bad.yaml'
    bad.write_text('medium: land\nA: [[1, 0]]\n')
    assert main(['validate', str(bad), str(zigzags[(56, 32)])]) == 2
    assert 'malformed model' in capsys.readouterr().err
    assert not (tmp_path / 'out.yaml').exists()


def test_model_file_round_trips(tmp_path):
    model = sysid.identify([_known_run(3)], 'land', order=3).model
    path = tmp_path / 'model.yaml'
    save_model(model, str(path))
    data = yaml.safe_load(path.read_text())
    assert data['inputs'] == ['port_cmd', 'stbd_cmd'] and data['outputs'] == ['u', 'v', 'r']
    assert {'A', 'B', 'C', 'D', 'K', 'u_offset', 'y_offset', 'fit_pct', 'dt_s'} <= set(data)
    back = load_model(str(path))
    for name in ('A', 'B', 'C', 'D', 'K', 'u_offset', 'y_offset'):
        np.testing.assert_array_equal(getattr(back, name), getattr(model, name))
    assert back.medium == 'land' and back.dt_s == model.dt_s and back.fit_pct == model.fit_pct
    # what the file says the equations are, with numpy alone
    u = np.full((400, 2), 10.0) + data['u_offset']
    np.testing.assert_allclose(state_space.simulate(back, u), state_space.simulate(model, u))


def _paper_pairs():
    from dukw_estimation.sysid_cli import _paper_reference
    pairs = _paper_reference(None)['zigzag_pairs']
    return [(medium, high, low) for medium in ('land', 'water') for high, low in pairs[medium]]


@pytest.mark.parametrize('medium,high,low', _paper_pairs())
def test_every_paper_zigzag_is_one_command_sysid_reads(medium, high, low, tmp_path):
    path = tmp_path / 'run.csv'
    maneuver.main(['zigzag', '--medium', medium, '--high', str(high), '--low', str(low),
                   '--lead-in', '2', '--csv', str(path)])
    run = sysid.resample(read_run(path, medium))
    sysid.check_run(run, medium)         # long enough, excited, of its medium
    assert run.duration_s == pytest.approx(32.0, abs=0.02)
    assert np.ptp(run.u_pct[:, 0]) == pytest.approx(high)   # from rest to the high side
