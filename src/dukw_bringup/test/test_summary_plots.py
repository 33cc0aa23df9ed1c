"""summary.json and the plots from a synthetic run bag (no DDS: messages serialized by rclpy)."""
import json
import math

import numpy as np
import pytest
from dukw_msgs.msg import DriveMode, DrivetrainStatus, SimTruth, Traction
from nav_msgs.msg import Odometry
from rclpy.serialization import serialize_message
from std_msgs.msg import String

from dukw_bringup.bag_io import BagWriter
from dukw_bringup.mission import MissionState, Progress
from dukw_bringup.plot_run import main as plot_run_main
from dukw_bringup.plot_run import previous_run_keys
from dukw_bringup.plots import PLOT_FILES
from dukw_bringup.summary import load_run, summarize_run, time_average

TYPES = {'odometry/filtered': 'nav_msgs/msg/Odometry', 'tracks/status':
         'dukw_msgs/msg/DrivetrainStatus', 'traction': 'dukw_msgs/msg/Traction',
         'drive_mode': 'dukw_msgs/msg/DriveMode', 'sim/truth': 'dukw_msgs/msg/SimTruth',
         'mission/status': 'std_msgs/msg/String'}


def write_run_bag(bag_dir, duration_s=20.0, with_status=True):
    """A 10 Hz run from x=-10 to x=+10 with a 40 A current spike from 5 to 6 s."""
    with BagWriter(bag_dir) as writer:
        for topic, msgtype in TYPES.items():
            writer.add_topic('/' + topic, msgtype)
        for k in range(int(duration_s * 10) + 1):
            t_s = k * 0.1
            stamp_ns = int(1e9 + t_s * 1e9)
            x = -10.0 + t_s
            odom = Odometry()
            odom.pose.pose.position.x = x
            odom.twist.twist.linear.x = 1.0
            status = DrivetrainStatus()
            status.port.current_a = 40.0 if 5.0 <= t_s < 6.0 else 30.0
            status.stbd.current_a = 20.0
            traction = Traction(port_slip=0.1 + 0.01 * math.sin(t_s), stbd_slip=-0.2,
                                submerged_volume_m3=max(0.0, 0.015 * x),
                                effective_weight_n=2894.0 - 100.0 * max(0.0, x),
                                weight_on_tracks_fraction=1.0)
            mode = DriveMode(mode=DriveMode.LAND if x < 0 else (
                DriveMode.TRANSITION if x < 5 else DriveMode.WATER), reason=f'x={x:.1f}')
            truth = SimTruth(x_m=x, z_m=-0.05 * x, port_slip=0.12, stbd_slip=-0.25,
                             submerged_volume_m3=0.01, effective_weight_n=2000.0)
            for topic, msg in (('odometry/filtered', odom), ('tracks/status', status),
                               ('traction', traction), ('drive_mode', mode),
                               ('sim/truth', truth)):
                writer.write('/' + topic, stamp_ns, serialize_message(msg))
        if with_status:
            done = Progress(state=MissionState.DONE, waypoints_total=2, reached_s=[9.0, 19.5],
                            elapsed_s=19.5, distance_m=0.0)
            writer.write('/mission/status', stamp_ns, serialize_message(String(
                data=done.to_json())))


def test_summary_figures_from_a_bag(tmp_path):
    write_run_bag(tmp_path / 'bag')
    run = load_run(tmp_path / 'bag')
    summary = summarize_run(run, current_limit_a=35.0, mission_name='m')
    assert summary['reached'] is True and summary['state'] == 'done'
    assert summary['time_s'] == pytest.approx(19.5)
    assert summary['waypoints_reached'] == 2
    assert [m['mode'] for m in summary['mode_timeline']] == ['LAND', 'TRANSITION', 'WATER']
    assert summary['mode_timeline'][1]['t_s'] == pytest.approx(10.0)
    port = summary['track_currents']['port']
    assert port['peak_a'] == pytest.approx(40.0)
    assert port['time_over_limit_s'] == pytest.approx(1.0, abs=0.01)
    assert port['mean_a'] == pytest.approx(30.5, abs=0.05)   # 1 s of 40 A in 20 s of 30 A
    assert summary['track_currents']['stbd']['peak_over_limit'] is False
    assert summary['prop_currents'] == {'port': None, 'stbd': None}
    assert summary['slip']['estimated']['stbd'] == {'min': -0.2, 'max': -0.2}
    assert summary['slip']['truth']['port']['max'] == pytest.approx(0.12)
    assert summary['submersion']['estimated']['max_submerged_volume_m3'] == pytest.approx(0.15)
    assert summary['submersion']['estimated']['min_effective_weight_n'] == pytest.approx(1894.0)
    assert summary['distance_m'] == pytest.approx(20.0)


def test_without_mission_status_the_run_is_not_reached(tmp_path):
    write_run_bag(tmp_path / 'bag', duration_s=2.0, with_status=False)
    summary = summarize_run(load_run(tmp_path / 'bag'), 35.0)
    assert summary['reached'] is False and summary['state'] == 'unknown'


def test_time_average_weights_by_duration():
    t = np.array([0.0, 1.0, 4.0])
    assert time_average(t, np.array([10.0, 20.0, 99.0])) == pytest.approx((10 + 60) / 4)
    assert math.isnan(time_average(np.array([]), np.array([])))


def test_plot_run_writes_summary_and_every_plot(tmp_path, capsys):
    write_run_bag(tmp_path / 'bag')
    assert plot_run_main([str(tmp_path)]) == 0
    out = capsys.readouterr().out.strip().splitlines()
    assert out[-1] == str(tmp_path)
    summary = json.loads((tmp_path / 'summary.json').read_text())
    for key in ('reached', 'time_s', 'mode_timeline', 'track_currents', 'slip', 'submersion'):
        assert key in summary
    assert summary['bag_topics']['/tracks/status'] == 201
    for name in PLOT_FILES:
        png = (tmp_path / name).read_bytes()
        assert png.startswith(b'\x89PNG') and len(png) > 10_000, name


def test_plot_run_keeps_the_main_jobs_keys_of_an_earlier_summary(tmp_path):
    (tmp_path / 'summary.json').write_text(json.dumps({'ending': 'mission done', 'x': 1}))
    assert previous_run_keys(tmp_path / 'summary.json') == {'ending': 'mission done'}
    (tmp_path / 'summary.json').write_text('{not json')
    assert previous_run_keys(tmp_path / 'summary.json') == {}
    assert previous_run_keys(tmp_path / 'none.json') == {}


def test_plot_run_on_a_folder_without_bag_is_a_clear_error(tmp_path, capsys):
    assert plot_run_main([str(tmp_path)]) == 2
    assert 'not a rosbag2 folder' in capsys.readouterr().err
