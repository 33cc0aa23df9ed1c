"""live_view_node: the running graph, live in Foxglove, over foxglove-sdk's WebSocket server.

Every ROS topic is forwarded as raw CDR with its ros2msg schema (live_forward), so the
3D panel gets /tf, /tf_static and robot_description, the map gets gps/fix, the plots get
any field. On top, scene entities (live_scene, drawn on ``/live/scene``): the beach, the
moving water surface (the simulator's own wave field with ``sim_world``), the vehicle in
base_link and its true pose as a ghost; the GPS track as LocationFix on ``/live/gps``;
``/live/limits`` (JSON) carries the continuous current limit for the current plots.
The beach and the mean sea level also go on ROS, latched (``live_view/beach``,
visualization_msgs/MarkerArray), so a run's bag draws them.
The server's URL is logged and latched on ``live_view/url`` (std_msgs/String).
"""
from __future__ import annotations

import foxglove
from rclpy.node import Node
from std_msgs.msg import String
from visualization_msgs.msg import MarkerArray

from dukw_bringup import live_foxglove as fg
from dukw_bringup.live_forward import GraphForwarder, SubscriberDemand
from dukw_bringup.live_markers import beach_markers
from dukw_bringup.live_scene import (TRUTH_ALPHA, LiveScene, SceneArea, sim_world_fields,
                                     site_ground, vehicle_parts)
from dukw_common.config import ConfigError
from dukw_common.description import FrameNames, VehicleModel
from dukw_common.node_tools import (STATE_QOS, ParamSpec, declare_parameters,
                                    run_node, vehicle_specs)
from dukw_common.vehicle import Vehicle

SPECS = [
    ParamSpec('host', 'WebSocket server address (0.0.0.0: every interface)'),
    ParamSpec('port', 'WebSocket server port (taken: any free port, logged)', min=0, max=65535),
    ParamSpec('rescan_period_s', 'seconds between graph scans for new topics', 0.05, 60.0),
    ParamSpec('water_rate_hz', 'water surface redraw rate, Hz', 0.1, 50.0),
    ParamSpec('latched_period_s', 'latched topics and fixed scene re-sent, s', 0.1, 60.0),
    ParamSpec('sim_world', "draw the simulator's beach and waves (false: the site's slope)"),
    ParamSpec('seed', "= sim_node seed: the simulator's sea state", min=0, max=2**31 - 1),
    ParamSpec('waves.model', '= sim_node waves.model (none | regular | irregular)'),
    ParamSpec('waves.significant_height_m', '= sim_node waves.significant_height_m', 0.0, 5.0),
    ParamSpec('waves.peak_period_s', '= sim_node waves.peak_period_s', 0.5, 30.0),
    *[ParamSpec(f'area.{n}', f'drawn area {n} (odom)', -1000.0, 1000.0)
      for n in SceneArea.__dataclass_fields__],
    *[ParamSpec(f'frames.{n}', f'frame id: {n}') for n in ('odom', 'base', 'truth')],
    ParamSpec('deck_thickness_m', '= robot_state_node deck_thickness_m', 0.001, 0.5),
]


class LiveViewNode(Node):
    """Serves the graph and the scene to Foxglove clients."""

    def __init__(self) -> None:
        super().__init__('live_view_node')
        p = self.p = declare_parameters(self, SPECS + vehicle_specs())
        try:
            self.scene = self._scene(p)
            vehicle = Vehicle.from_params(p)
            model = VehicleModel.build(vehicle.body, vehicle.sensors,
                                       FrameNames(base=p['frames.base']), p['deck_thickness_m'])
        except ValueError as exc:
            raise ConfigError(f'live_view_node: {exc}') from exc
        self.parts, self.ghost = vehicle_parts(model), vehicle_parts(model, TRUTH_ALPHA)
        self.current_limit_a = vehicle.drivetrain.continuous_current_limit_a
        self.demand = SubscriberDemand()      # the clients' subscriptions (server thread)
        self.server = self._start_server(p['host'], int(p['port']))
        self.url = f'ws://{p["host"]}:{self.server.port}'
        self.get_logger().info(f'Foxglove live view: {self.url} (Open connection -> '
                               'Foxglove WebSocket; layout config/foxglove/dukw_layout.json)')
        self.create_publisher(String, 'live_view/url', STATE_QOS).publish(String(data=self.url))
        self.create_publisher(MarkerArray, 'live_view/beach', STATE_QOS).publish(beach_markers(
            self.scene.beach(), self.scene.sea_level(), p['frames.odom'],
            self.get_clock().now().to_msg()))
        self.scene_ch = foxglove.channels.SceneUpdateChannel('/live/scene')
        self.gps_ch = foxglove.channels.LocationFixChannel('/live/gps')
        self.limits_ch = foxglove.Channel('/live/limits')
        self.forwarder = GraphForwarder(self, taps={self.resolve_topic_name('gps/fix'):
                                                    self.on_fix}, demand=self.demand)
        self.create_timer(p['rescan_period_s'], self.forwarder.scan)
        self.create_timer(1.0 / p['water_rate_hz'], self.on_water)
        self.create_timer(p['latched_period_s'], self.on_latched)
        self.on_latched()

    def _scene(self, p) -> LiveScene:
        area = SceneArea.from_params(p)
        if not p['sim_world']:
            return LiveScene(area, site_ground(p['site.beach_slope_rad'],
                                               p['site.sea_floor_depth_m']))
        overrides = {k: p[k] for k in ('waves.model', 'waves.significant_height_m',
                                       'waves.peak_period_s')}
        return LiveScene(area, *sim_world_fields(overrides, int(p['seed'])))

    def _start_server(self, host: str, port: int):
        try:
            return foxglove.start_server(name='dukw-ling', host=host, port=port,
                                         server_listener=self.demand)
        except Exception as exc:  # port taken: the view must not stop the stack
            self.get_logger().warning(f'port {port} unusable ({exc}): taking a free one')
            return foxglove.start_server(name='dukw-ling', host=host, port=0,
                                         server_listener=self.demand)

    def now_ns(self) -> int:
        """Node clock (sim time under use_sim_time), ns."""
        return self.get_clock().now().nanoseconds

    def on_water(self) -> None:
        if not self.scene_ch.has_sinks():      # no viewer: no mesh (most of the view's CPU)
            return
        t_ns = self.now_ns()
        water = self.scene.water(t_ns * 1e-9)
        self.scene_ch.log(fg.scene(fg.mesh_entity(water, self.p['frames.odom'], t_ns)),
                          log_time=t_ns)

    def on_latched(self) -> None:
        t_ns = self.now_ns()
        self.forwarder.relog_latched()
        self.limits_ch.log({'continuous_current_limit_a': self.current_limit_a}, log_time=t_ns)
        if not self.scene_ch.has_sinks():      # no viewer: no meshes
            return
        self.scene_ch.log(fg.scene(
            fg.mesh_entity(self.scene.beach(), self.p['frames.odom'], t_ns),
            fg.parts_entity('vehicle', self.parts, self.p['frames.base'], t_ns),
            fg.parts_entity('vehicle_truth', self.ghost, self.p['frames.truth'], t_ns)),
            log_time=t_ns)

    def on_fix(self, msg) -> None:
        """sensor_msgs/NavSatFix -> LocationFix on the map."""
        t_ns = self.now_ns()
        cov = [msg.position_covariance[i] for i in range(9)]
        self.gps_ch.log(fg.location_fix(t_ns, msg.header.frame_id, msg.latitude,
                                        msg.longitude, msg.altitude, cov), log_time=t_ns)

    def on_shutdown(self) -> None:
        """Close the WebSocket server."""
        self.server.stop()


def main(args=None) -> int:
    """Console-script entry point."""
    return run_node(LiveViewNode, args)


if __name__ == '__main__':
    raise SystemExit(main())
