"""Fault matrix, access control set-up (README "Security").

Row: a stranger on another machine of the network. Must: the stacks keep the ROS graph
on the vehicle (localhost discovery) -- tests in src/dukw_bringup/test/test_bringup.py.
Row: SROS2 on a ROS 2 install with DDS-Security. Checked as far as the PyPI build
allows: the policy's structure, one enclave per process of both boat stack shapes (one per
node, or the composed chain's with each of its nodes' profiles), in each shape exactly one
publishing enclave per safety topic and one server and one client per state-changing
service; `bringup` puts each process in its enclave; and a secured start on the PyPI Fast
DDS (no DDS-Security) is refused with exit 2 and a message, never run unsecured.
"""
import os
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path
from xml.etree import ElementInclude

import pytest

from dukw_bringup.bringup import load_stack, node_command, stack_path
from dukw_common.testing import executable

ROOT = Path(__file__).resolve().parents[2]
POLICY = ROOT / 'config' / 'sros2' / 'dukw_policy.xml'
SAFETY_TOPICS = ('tracks/cmd', 'props/cmd', 'drive_mode', 'authority', 'cmd_vel')
SAFETY_SERVICES = ('set_mode', 'set_pose')
BOAT_SHAPES = ('boat', 'boat_composed')
CONSOLES = ('/dukw/operator', '/dukw/recorder')   # enclaves outside the stack files
QUALIFIERS = {'topics': ('publish', 'subscribe'), 'services': ('reply', 'request')}


def _policy():
    """The policy with its includes (nested ones relative to their own file) resolved."""
    root = ET.parse(POLICY).getroot()
    ElementInclude.include(root, base_url=str(POLICY))
    return root


def _shape_enclaves(shape):
    """The enclaves a boat stack shape runs in: one per process, plus the consoles."""
    return {f'/dukw/{spec.name}' for spec in load_stack(stack_path(shape)).nodes} | set(CONSOLES)


def _grants(root, shape):
    """{(enclave, kind, qualifier): set of names} of one stack shape's enclaves."""
    grants = {}
    for enclave in root.iter('enclave'):
        if enclave.get('path') not in _shape_enclaves(shape):
            continue
        for profile in enclave.iter('profile'):
            for group in profile:
                assert group.tag in QUALIFIERS, group.tag
                for qualifier in QUALIFIERS[group.tag]:
                    value = group.get(qualifier)
                    if value is None:
                        continue
                    assert value in ('ALLOW', 'DENY')
                    names = {e.text.strip() for e in group}
                    grants.setdefault((enclave.get('path'), group.tag, qualifier),
                                      set()).update(names)
    return grants


@pytest.mark.parametrize('shape', BOAT_SHAPES)
def test_policy_has_one_enclave_per_process_with_its_nodes_profiles(shape):
    root = _policy()
    assert root.tag == 'policy' and root.get('version') == '0.2.0'
    enclaves = {e.get('path'): e for e in root.find('enclaves')}
    for spec in load_stack(stack_path(shape)).nodes:
        enclave = enclaves[f'/dukw/{spec.name}']
        profiles = list(enclave.iter('profile'))
        assert [p.get('node') for p in profiles] == list(spec.node_names)
        assert all(p.get('ns') == '/' for p in profiles)
        assert all(p.find('topics') is not None for p in profiles)   # includes resolved


def _text(profile):
    """A profile's XML without the whitespace that follows it in its enclave."""
    profile.tail = None
    return ET.tostring(profile)


def test_a_composed_nodes_profile_is_the_one_of_its_own_enclave():
    enclaves = {e.get('path'): e for e in _policy().find('enclaves')}
    chain = {p.get('node'): _text(p) for p in enclaves['/dukw/control_chain'].iter('profile')}
    for node, profile in chain.items():
        (alone,) = enclaves[f'/dukw/{node}'].iter('profile')
        assert _text(alone) == profile


@pytest.mark.parametrize('shape', BOAT_SHAPES)
@pytest.mark.parametrize('topic', SAFETY_TOPICS)
def test_each_safety_topic_has_exactly_one_publishing_enclave(topic, shape):
    publishers = [enclave for (enclave, kind, qualifier), names
                  in _grants(_policy(), shape).items()
                  if kind == 'topics' and qualifier == 'publish' and topic in names]
    assert len(publishers) == 1, publishers


@pytest.mark.parametrize('shape', BOAT_SHAPES)
@pytest.mark.parametrize('service', SAFETY_SERVICES)
def test_each_state_changing_service_has_one_server_and_one_client(service, shape):
    grants = _grants(_policy(), shape)
    for qualifier, expected in (('reply', 1), ('request', 1)):
        holders = [enclave for (enclave, kind, q), names in grants.items()
                   if kind == 'services' and q == qualifier and service in names]
        assert len(holders) == expected, (qualifier, holders)


def test_bringup_runs_each_node_in_its_enclave_when_security_is_on():
    spec = load_stack(stack_path('boat')).node('ekf_node')
    command = node_command(spec, [], secure=True)
    assert command[command.index('--enclave') + 1] == '/dukw/ekf_node'
    assert '--enclave' not in node_command(spec, [])
    chain = load_stack(stack_path('boat_composed')).node('control_chain')
    command = node_command(chain, [], secure=True)
    assert command[command.index('--enclave') + 1] == '/dukw/control_chain'


def test_secured_start_on_the_pypi_dds_is_refused_not_run_unsecured(tmp_path):
    enclave = tmp_path / 'keystore' / 'enclaves' / 'dukw' / 'mode_manager_node'
    enclave.mkdir(parents=True)
    for name in ('identity_ca.cert.pem', 'cert.pem', 'key.pem', 'permissions_ca.cert.pem',
                 'governance.p7s', 'permissions.p7s'):
        (enclave / name).write_text('placeholder: the PyPI Fast DDS never reads it\n')
    env = {'ROS_SECURITY_ENABLE': 'true', 'ROS_SECURITY_STRATEGY': 'Enforce',
           'ROS_SECURITY_KEYSTORE': str(tmp_path / 'keystore')}
    proc = subprocess.run([str(executable('dukw_control', 'mode_manager_node')), '--ros-args',
                           '--enclave', '/dukw/mode_manager_node'], capture_output=True,
                          text=True, timeout=60, env={**os.environ, **env})
    assert proc.returncode == 2, proc.stderr
    assert 'security' in proc.stderr.lower() and 'Traceback' not in proc.stderr, proc.stderr
