"""The committed Foxglove layout is the one built from config, over topics the stack has."""
import json
import re
from pathlib import Path

from dukw_bringup.live_layout import layout_json
from dukw_common.vehicle import Vehicle

LAYOUT = Path(__file__).resolve().parents[3] / 'config' / 'foxglove' / 'dukw_layout.json'
#: Topics a main-job bag holds (test_main_job checks them) and the live view's own.
RECORDED = {'/traction', '/sim/truth', '/tracks/status', '/props/status', '/odometry/filtered',
            '/cmd_vel', '/drive_mode', '/gps/fix', '/robot_description', '/live_view/beach'}
LIVE_ONLY = {'/live/scene', '/live/limits'}


def test_committed_layout_is_the_generated_one():
    assert LAYOUT.read_text() == layout_json(), \
        'regenerate: python -m dukw_bringup.live_layout config/foxglove/dukw_layout.json'


def test_layout_shows_3d_map_plots_and_the_mode_timeline_over_known_topics():
    text = LAYOUT.read_text()
    doc = json.loads(text)
    panels = re.findall(r'"panelType": "(\w+)"', text)
    assert sorted(set(panels)) == ['Map', 'Plot', 'StateTransitions', 'ThreeDee']
    topics = set(re.findall(r'"(/[a-z_/]+?)(?:\.|")', text))
    assert topics <= RECORDED | LIVE_ONLY, topics - RECORDED - LIVE_ONLY
    assert {'/traction', '/tracks/status', '/drive_mode', '/robot_description'} <= topics
    limit_a = Vehicle.load().drivetrain.continuous_current_limit_a
    assert f'currents vs the {limit_a:g} A' in text and doc['content']['type'] == 'split'
