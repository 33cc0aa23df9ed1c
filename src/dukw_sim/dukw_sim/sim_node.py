"""sim_node: skeleton (filled in by its own issue)."""
from rclpy.node import Node

from dukw_common.node_tools import ParamSpec, declare_parameters, run_node


class SimNode(Node):
    """Skeleton: declares its parameters from config/ and idles."""

    def __init__(self) -> None:
        super().__init__('sim_node')
        self.params = declare_parameters(self, [
            ParamSpec('rate_hz', 'main loop rate, Hz', min=0.1, max=1000.0),
        ])


def main(args=None) -> int:
    """Console-script entry point."""
    return run_node(SimNode, args)


if __name__ == '__main__':
    raise SystemExit(main())
