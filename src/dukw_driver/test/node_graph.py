"""A driver node under test and a probe node in one isolated context (for node tests)."""
from diagnostic_msgs.msg import DiagnosticArray

from dukw_common.node_tools import SENSOR_QOS, parameter_overrides
from dukw_common.testing import spin_until


class NodeGraph:
    """Builds ``node_class`` with parameter overrides; records topics and /diagnostics."""

    def __init__(self, probe, executor, node_class, **overrides):
        self.probe, self.executor = probe, executor
        self.node = node_class(context=probe.context,
                               parameter_overrides=parameter_overrides(overrides))
        executor.add_node(self.node)
        self.diag = self.record(DiagnosticArray, '/diagnostics', qos=10)

    def record(self, msg_type, topic, qos=SENSOR_QOS) -> list:
        """Subscribe the probe to ``topic``; return the list its messages are appended to."""
        messages = []
        self.probe.create_subscription(msg_type, topic, messages.append, qos)
        return messages

    def spin_until(self, predicate, timeout_s=10.0):
        """Spin until ``predicate()``; generous default for a loaded machine."""
        return spin_until(self.executor, predicate, timeout_s)

    def status(self, device):
        """The latest DiagnosticStatus whose name ends with ``device`` (None if none yet)."""
        for array in reversed(self.diag):
            for status in array.status:
                if status.name.endswith(device):
                    return status
        return None

    def value(self, device, key, default=None):
        """A key's value in the device's latest status."""
        status = self.status(device)
        return {kv.key: kv.value for kv in status.values}.get(key, default) if status \
            else default

    def close(self):
        self.node.on_shutdown()
        self.executor.remove_node(self.node)
        self.node.destroy_node()
