"""The DUKW-Ling stack for a full ROS 2 install (launch and launch_ros from apt).

    ros2 launch dukw_bringup stack.launch.py sim:=true      # simulator instead of drivers
    ros2 launch dukw_bringup stack.launch.py sim:=false params_file:=/path/boat.yaml
    ros2 launch dukw_bringup stack.launch.py composed:=true  # the chain in one process

Starts the nodes that config/stack_sim.yaml or config/stack_boat.yaml list (with
composed:=true stack_sim_composed.yaml / stack_boat_composed.yaml; the same files the
`bringup` runner reads, so both start the same stack; a ``composes`` entry is one
`compose` process running those nodes, not renamed), each with
the parameter file and its per-node ROS arguments. With sim:=true every node
but sim_node runs on the simulator's /clock (use_sim_time). Any node exiting
shuts the whole launch down: nothing is restarted silently.
"""
from pathlib import Path

import yaml
from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction, Shutdown
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

CONFIG_DIR = Path(get_package_share_directory('dukw_common')) / 'config'


def _nodes(context):
    sim = LaunchConfiguration('sim').perform(context).lower() in ('true', '1', 'yes')
    params_file = LaunchConfiguration('params_file').perform(context)
    composed = LaunchConfiguration('composed').perform(context).lower() in ('true', '1', 'yes')
    stack_file = CONFIG_DIR / (f"stack_{'sim' if sim else 'boat'}"
                               f"{'_composed' if composed else ''}.yaml")
    stack = yaml.safe_load(stack_file.read_text())['stack']
    nodes = []
    for entry in stack['nodes']:
        parameters = [params_file]
        if stack.get('clock_node') not in (None, entry['name']):
            parameters.append({'use_sim_time': True})
        composes = [str(n) for n in entry.get('composes', [])]
        nodes.append(Node(
            package=entry['package'], executable=entry['executable'],
            name=None if composes else entry['name'], arguments=composes,
            parameters=parameters, ros_arguments=[str(a) for a in entry.get('args', [])],
            output='screen', emulate_tty=True,
            additional_env=({'ROS_AUTOMATIC_DISCOVERY_RANGE': stack['discovery_range']}
                            if stack.get('discovery_range') else None),
            on_exit=Shutdown(reason=f"{entry['name']} exited")))
    return nodes


def generate_launch_description():
    """Launch arguments sim and params_file, then the stack's nodes."""
    return LaunchDescription([
        DeclareLaunchArgument('sim', default_value='true',
                              description='true: sim_node instead of the drivers'),
        DeclareLaunchArgument('composed', default_value='false',
                              description='true: ekf, mode manager and controller in one process'),
        DeclareLaunchArgument('params_file', default_value=str(CONFIG_DIR / 'dukw.yaml'),
                              description='ROS 2 parameter file for every node'),
        OpaqueFunction(function=_nodes),
    ])
