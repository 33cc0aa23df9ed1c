"""Read a YAML file of the bring-up (stack file, mission file) with one clear error."""
from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from dukw_common.config import ConfigError


def read_yaml(path: str | Path, what: str) -> Any:
    """The parsed document at ``path``; ConfigError naming ``what`` and the path otherwise."""
    path = Path(path)
    try:
        return yaml.safe_load(path.read_text())
    except OSError as exc:
        raise ConfigError(f'cannot read {what} {path}: {exc.strerror}') from exc
    except yaml.YAMLError as exc:
        raise ConfigError(f'{path} is not valid YAML: {exc}') from exc
