"""Settings from the stack's parameter file, for the control cores' tests."""
import pytest

from dukw_common.config import node_params
from dukw_control import controller, modes


@pytest.fixture
def controller_settings():
    return controller.settings_from_params(node_params('drive_controller_node'))


@pytest.fixture
def mode_settings():
    return modes.settings_from_params(node_params('mode_manager_node'))
