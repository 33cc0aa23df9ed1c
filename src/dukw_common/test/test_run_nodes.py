"""run_nodes: several nodes on one executor; on SIGINT each node's on_shutdown runs while
the context is up, in reverse order (the commanding node, listed last, first)."""
import os
import signal

import pytest
from rclpy.node import Node

from dukw_common.node_tools import run_nodes

pytestmark = [pytest.mark.ros, pytest.mark.timeout(60)]


class Recording(Node):
    """Notes its ticks and its shutdown (and whether the context was still up)."""

    def __init__(self, name, log, stop_after=0):
        super().__init__(name)
        self.log, self.ticks, self.stop_after = log, 0, stop_after
        self.create_timer(0.01, self.tick)

    def tick(self):
        self.ticks += 1
        if self.stop_after and self.ticks == self.stop_after:
            os.kill(os.getpid(), signal.SIGINT)        # as Ctrl-C

    def on_shutdown(self):
        self.log.append((self.get_name(), self.ticks, self.context.ok()))


def test_every_node_spins_and_shuts_down_in_reverse_order():
    handlers = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    log = []
    try:
        code = run_nodes(lambda: [Recording('first', log), Recording('last', log, 20)],
                         args=['run_nodes_test'])
    finally:
        for signum, handler in handlers.items():
            signal.signal(signum, handler)
    assert code == 0
    assert [name for name, _, _ in log] == ['last', 'first']
    assert all(ticks >= 10 and up for _, ticks, up in log), log
