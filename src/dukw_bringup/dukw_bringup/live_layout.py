"""The Foxglove layout of the live view and of the run's bag, built with foxglove-sdk's
typed ``foxglove.layouts`` (so it is a valid layout), written to
config/foxglove/dukw_layout.json:

    python -m dukw_bringup.live_layout config/foxglove/dukw_layout.json

3D (the URDF from robot_description over the /live/scene beach and water, following
base_link in odom, the true pose's ghost; in a bag the beach is live_view/beach), the map
(gps/fix and /live/gps), plots of slip, submersion, track and propeller currents against
the continuous limit, speed, and the drive mode as a state timeline. Everything but
/live/* is a recorded ROS topic, so the same layout opens a run's bag.
"""
from __future__ import annotations

import json
import sys

import foxglove.layouts as fl

from dukw_common.vehicle import Vehicle


def _plot(title: str, series: list[tuple[str, str]], y_label: str) -> fl.PlotPanel:
    return fl.PlotPanel(title=title, config=fl.PlotConfig(
        paths=[fl.PlotSeries(value=path, label=label) for path, label in series],
        y_axis_label=y_label, show_legend=True))


def _three_d() -> fl.ThreeDeePanel:
    return fl.ThreeDeePanel(title='vehicle on the beach', config=fl.ThreeDeeConfig(
        follow_tf='base_link', fixed_frame='odom',
        topics={'/live/scene': fl.BaseRendererSceneUpdateTopicSettings(visible=True),
                '/live_view/beach': fl.BaseRendererRosMarkerTopicSettings(visible=True)},
        layers={'grid': fl.BaseRendererGridLayerSettings(layer_id='foxglove.Grid'),
                'urdf': fl.BaseRendererUrdfLayerSettings(
                    layer_id='foxglove.Urdf', source_type='topic',
                    topic='/robot_description', display_mode='visual')}))


def build_layout(current_limit_a: float) -> fl.Layout:
    """The layout; ``current_limit_a`` only names the currents plot."""
    plots = [
        _plot('track slip', [('/traction.port_slip', 'EKF port'),
                             ('/traction.stbd_slip', 'EKF stbd'),
                             ('/sim/truth.port_slip', 'true port'),
                             ('/sim/truth.stbd_slip', 'true stbd')], 'slip'),
        _plot('submersion', [('/traction.submerged_volume_m3', 'EKF volume m3'),
                             ('/sim/truth.submerged_volume_m3', 'true volume m3'),
                             ('/traction.weight_on_tracks_fraction', 'EKF weight on tracks')],
              'm3 / share'),
        _plot(f'currents vs the {current_limit_a:g} A continuous limit',
              [('/tracks/status.port.current_a', 'track port'),
               ('/tracks/status.stbd.current_a', 'track stbd'),
               ('/props/status.port.current_a', 'prop port'),
               ('/props/status.stbd.current_a', 'prop stbd'),
               ('/live/limits.continuous_current_limit_a', 'limit (live)')], 'A'),
        _plot('speed', [('/odometry/filtered.twist.twist.linear.x', 'EKF surge'),
                        ('/sim/truth.surge_mps', 'true surge'),
                        ('/cmd_vel.twist.linear.x', 'cmd_vel')], 'm/s'),
    ]
    modes = fl.StateTransitionsPanel(title='drive mode', config=fl.StateTransitionsConfig(
        paths=[fl.StateTransitionsSeries(value='/drive_mode.mode', label='mode')]))
    map_panel = fl.MapPanel(title='GPS track', config=fl.MapConfig(follow_topic='/gps/fix'))
    left = fl.SplitContainer(direction='column', items=[
        fl.SplitItem(proportion=3, content=_three_d()),
        fl.SplitItem(proportion=2, content=map_panel)])
    right = fl.SplitContainer(direction='column', items=[
        *[fl.SplitItem(proportion=1, content=p) for p in plots],
        fl.SplitItem(proportion=0.6, content=modes)])
    return fl.Layout(content=fl.SplitContainer(direction='row', items=[
        fl.SplitItem(proportion=3, content=left), fl.SplitItem(proportion=2, content=right)]))


def layout_json() -> str:
    """The layout of the stack's configuration, as the committed JSON text."""
    limit_a = Vehicle.load().drivetrain.continuous_current_limit_a
    return json.dumps(json.loads(build_layout(limit_a).to_json()), indent=1) + '\n'


if __name__ == '__main__':
    with open(sys.argv[1], 'w') as out:
        out.write(layout_json())
