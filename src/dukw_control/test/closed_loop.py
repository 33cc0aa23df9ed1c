"""The closed-loop harness now lives in package code: dukw_bringup.stack_harness."""
from dukw_bringup.stack_harness import (STATUS_EVERY, ClosedLoop, Record,  # noqa: F401
                                        default_controller_settings, default_mode_settings)
