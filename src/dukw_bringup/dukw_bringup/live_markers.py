"""live_scene's beach as ROS visualization_msgs, so a run's bag draws it too (rviz,
Foxglove): one latched MarkerArray on ``live_view/beach`` with the sand and sea bed and the
mean sea level. The moving water surface stays live-only (/live/scene): at 5 Hz its mesh
would add about 0.4 MB/s to every bag."""
from __future__ import annotations

from geometry_msgs.msg import Point
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker, MarkerArray

from dukw_bringup.live_scene import Mesh


def _color(rgba) -> ColorRGBA:
    return ColorRGBA(r=float(rgba[0]), g=float(rgba[1]), b=float(rgba[2]), a=float(rgba[3]))


def mesh_marker(mesh: Mesh, frame_id: str, stamp, marker_id: int) -> Marker:
    """A TRIANGLE_LIST marker of ``mesh`` (corners expanded: markers have no indices)."""
    marker = Marker(ns=mesh.name, id=marker_id, type=Marker.TRIANGLE_LIST, action=Marker.ADD,
                    color=_color(mesh.rgba), frame_locked=False)
    marker.header.frame_id, marker.header.stamp = frame_id, stamp
    marker.pose.orientation.w = 1.0
    marker.scale.x = marker.scale.y = marker.scale.z = 1.0
    marker.points = [Point(x=float(x), y=float(y), z=float(z))
                     for x, y, z in mesh.points[mesh.indices]]
    return marker


def beach_markers(beach: Mesh, sea_level: Mesh, frame_id: str, stamp) -> MarkerArray:
    """The beach and the mean sea level, for the bag."""
    return MarkerArray(markers=[mesh_marker(beach, frame_id, stamp, 0),
                                mesh_marker(sea_level, frame_id, stamp, 1)])
