"""The live view: a Foxglove WebSocket client (websockets) sees the running graph.

sim_node, robot_state_node and live_view_node run as processes; the probe learns the
server's URL from the latched ``live_view/url`` and connects with Foxglove's subprotocol.
"""
import asyncio
import json

import pytest
import websockets
from std_msgs.msg import String

from dukw_bringup.bag_io import typestore
from dukw_common.node_tools import STATE_QOS
from dukw_common.testing import NodeProcess, ros_node, spin_until
from dukw_common.vehicle import Vehicle

pytestmark = [pytest.mark.ros, pytest.mark.slow]
STARTUP_S = 60.0
UNKNOWN = 'Unknown channel ID: '
WANTED = {'/tf', '/tf_static', '/robot_description', '/sim/truth', '/gps/fix',
          '/live/scene', '/live/gps', '/live/limits', '/live_view/beach'}


def complete(received: dict) -> bool:
    """Every wanted topic came, and a scene update with the (moving) water surface."""
    return all(received.get(t) for t in WANTED) and any(
        b'water' in m for m in received['/live/scene'])


async def watch(url: str, seconds: float) -> tuple[dict, dict]:
    """Channels advertised and the messages received per topic within ``seconds``."""
    channels, received = {}, {}
    async with websockets.connect(url, subprotocols=['foxglove.sdk.v1']) as ws:
        loop = asyncio.get_running_loop()
        deadline = loop.time() + seconds
        subscribed: dict[int, str] = {}
        statuses = []
        while loop.time() < deadline and not complete(received):
            try:
                frame = await asyncio.wait_for(ws.recv(), deadline - loop.time())
            except asyncio.TimeoutError:
                break
            if isinstance(frame, str):
                op = json.loads(frame)
                if op['op'] == 'advertise':       # a channel may be advertised twice
                    new = {c['id']: c for c in op['channels']
                           if c['topic'] in WANTED and c['id'] not in subscribed}
                    channels.update({c['topic']: c for c in new.values()})
                    subscribed.update({cid: c['topic'] for cid, c in new.items()})
                    for cid in new:
                        await ws.send(json.dumps({'op': 'subscribe', 'subscriptions': [
                            {'id': cid, 'channelId': cid}]}))
                elif op['op'] == 'status' and op['message'].startswith(UNKNOWN):
                    # foxglove-sdk 0.30.3 may advertise a channel to a client just before
                    # it accepts subscriptions to it (seen under load): ask again
                    await asyncio.sleep(0.2)
                    cid = int(op['message'][len(UNKNOWN):])
                    await ws.send(json.dumps({'op': 'subscribe', 'subscriptions': [
                        {'id': cid, 'channelId': cid}]}))
                elif op['op'] == 'status':
                    statuses.append(op)
            elif frame[0] == 1:                          # message data
                topic = subscribed[int.from_bytes(frame[1:5], 'little')]
                received.setdefault(topic, []).append(bytes(frame[13:]))
    assert not statuses, statuses                    # the server refused nothing
    return channels, received


def test_a_websocket_client_gets_the_graph_and_the_scene():
    procs = [NodeProcess('dukw_sim', 'sim_node'),
             NodeProcess('dukw_bringup', 'robot_state_node'),
             NodeProcess('dukw_bringup', 'live_view_node', ['--ros-args', '-p', 'port:=0'])]
    try:
        with ros_node('live_probe') as (node, executor):
            urls = []
            node.create_subscription(String, 'live_view/url', urls.append, STATE_QOS)
            assert spin_until(executor, lambda: urls, STARTUP_S), procs[2].stderr
        url = urls[-1].data
        assert url.startswith('ws://127.0.0.1:') and not url.endswith(':0')
        channels, received = asyncio.run(watch(url, 40.0))
    finally:
        codes = [p.stop() for p in procs]
    assert codes == [0, 0, 0], [p.stderr[-2000:] for p in procs]
    assert set(channels) == WANTED, channels
    assert channels['/tf']['schemaName'] == 'tf2_msgs/msg/TFMessage'
    assert channels['/tf']['encoding'] == 'cdr'
    assert channels['/live/scene']['schemaName'] == 'foxglove.SceneUpdate'
    assert channels['/live/gps']['schemaName'] == 'foxglove.LocationFix'
    missing = sorted(t for t in WANTED if not received.get(t))
    assert not missing, (missing, {t: c['id'] for t, c in channels.items()})
    store = typestore()
    tf = store.deserialize_cdr(received['/tf'][-1], 'tf2_msgs/msg/TFMessage')
    assert tf.transforms[0].child_frame_id == 'base_link_truth'
    static = store.deserialize_cdr(received['/tf_static'][-1], 'tf2_msgs/msg/TFMessage')
    assert {'imu_link', 'gps_link', 'port_hull'} <= {t.child_frame_id for t in static.transforms}
    limit_a = Vehicle.load().drivetrain.continuous_current_limit_a
    assert json.loads(received['/live/limits'][-1]) == {'continuous_current_limit_a': limit_a}
    assert complete(received)                   # incl. the water entity (its id in the bytes)
    beach = store.deserialize_cdr(received['/live_view/beach'][-1],
                                  'visualization_msgs/msg/MarkerArray')
    assert [m.ns for m in beach.markers] == ['beach', 'sea_level']
    assert all(m.header.frame_id == 'odom' and len(m.points) % 3 == 0 for m in beach.markers)


class _Channel:
    """What the foxglove server hands its listener: a channel view with its topic."""

    def __init__(self, topic: str) -> None:
        self.topic = topic


def test_a_topic_is_subscribed_only_while_a_viewer_wants_it():
    """Like foxglove_bridge: no viewer, no ROS subscription on the 100 Hz topics (the stack's
    CPU); a client's subscription brings it at the next scan, its unsubscription drops it."""
    from dukw_bringup.live_forward import GraphForwarder, SubscriberDemand
    with ros_node('live_demand_probe') as (node, executor):
        pub = node.create_publisher(String, 'live_demand/chatter', 10)
        demand = SubscriberDemand()
        forwarder = GraphForwarder(node, demand=demand)

        def subscribers_after_scan() -> int:
            spin_until(executor, lambda: False, 0.2)
            forwarder.scan()
            spin_until(executor, lambda: False, 0.2)
            return pub.get_subscription_count()
        assert spin_until(executor, lambda: (forwarder.scan() or True)
                          and '/live_demand/chatter' in forwarder.channels, 10.0)
        assert subscribers_after_scan() == 0                 # advertised, not subscribed
        for client in (1, 2):
            demand.on_subscribe(client, _Channel('/live_demand/chatter'))
        assert subscribers_after_scan() == 1                 # one subscription for both
        demand.on_unsubscribe(1, _Channel('/live_demand/chatter'))
        assert subscribers_after_scan() == 1                 # the other client still wants it
        demand.on_unsubscribe(2, _Channel('/live_demand/chatter'))
        assert subscribers_after_scan() == 0
