"""Load the stack's ROS 2 parameter files without ROS (for cores and offline tools).

A parameter file has blocks ``<node_name>: {ros__parameters: {...}}``; the block
``/**`` applies to every node. Nested dictionaries become dotted names, as ROS 2
does (``vehicle: {mass_kg: 1}`` -> ``vehicle.mass_kg``).
"""
from __future__ import annotations

import math
import os
from dataclasses import fields
from pathlib import Path
from typing import Any, Mapping

import yaml

CONFIG_ENV = 'DUKW_CONFIG'
CONFIG_FILE = 'dukw.yaml'
ParamValue = bool | int | float | str | list


class ConfigError(ValueError):
    """A parameter file is missing, malformed, or lacks a needed parameter."""


def default_config_path() -> Path:
    """Return the parameter file to use: $DUKW_CONFIG, the source tree's, or the installed one."""
    env = os.environ.get(CONFIG_ENV)
    if env:
        return Path(env)
    here = Path(__file__).resolve()
    for parent in here.parents:  # a source checkout or a --symlink-install build
        candidate = parent / 'config' / CONFIG_FILE
        if candidate.is_file() and (parent / 'src').is_dir():
            return candidate
    try:
        from ament_index_python.packages import get_package_share_directory
        return Path(get_package_share_directory('dukw_common')) / 'config' / CONFIG_FILE
    except Exception as exc:  # PackageNotFoundError, or no ament index at all
        raise ConfigError(
            f'cannot find {CONFIG_FILE}: set {CONFIG_ENV} or install dukw_common ({exc})') from exc


def flatten(tree: Mapping[str, Any], prefix: str = '') -> dict[str, ParamValue]:
    """Flatten nested dictionaries into ROS 2 dotted parameter names."""
    flat: dict[str, ParamValue] = {}
    for key, value in tree.items():
        name = f'{prefix}{key}'
        if isinstance(value, Mapping):
            flat.update(flatten(value, name + '.'))
        else:
            flat[name] = value
    return flat


def load_file(path: str | os.PathLike | None = None) -> dict[str, dict[str, ParamValue]]:
    """Read a parameter file into ``{node_name: {dotted_name: value}}``; raise ConfigError."""
    path = Path(path) if path is not None else default_config_path()
    try:
        text = path.read_text()
    except OSError as exc:
        raise ConfigError(f'cannot read parameter file {path}: {exc.strerror}') from exc
    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise ConfigError(f'{path} is not valid YAML: {exc}') from exc
    if not isinstance(doc, dict):
        raise ConfigError(f'{path}: expected a mapping of node names at the top level')
    nodes: dict[str, dict[str, ParamValue]] = {}
    for node, block in doc.items():
        if not isinstance(block, dict) or not isinstance(block.get('ros__parameters'), dict):
            raise ConfigError(f'{path}: block {node!r} has no "ros__parameters" mapping')
        nodes[str(node).lstrip('/') or '**'] = flatten(block['ros__parameters'])
    return nodes


def node_params(node_name: str, path: str | os.PathLike | None = None) -> dict[str, ParamValue]:
    """Return the parameters one node sees: the shared ``/**`` block overlaid by its own."""
    nodes = load_file(path)
    params = dict(nodes.get('**', {}))
    params.update(nodes.get(node_name, {}))
    return params


def shared_params(path: str | os.PathLike | None = None) -> dict[str, ParamValue]:
    """Return the shared ``/**`` block (vehicle, drivetrain, soil, site...)."""
    return dict(load_file(path).get('**', {}))


def require(params: Mapping[str, ParamValue], name: str, kind: type = float) -> Any:
    """Return ``params[name]`` as ``kind``; raise ConfigError naming it if absent or bad."""
    if name not in params:
        raise ConfigError(f'missing parameter {name!r}')
    value = params[name]
    try:
        if kind is float:
            if isinstance(value, bool):
                raise TypeError
            out = float(value)
            if not math.isfinite(out):
                raise ValueError
            return out
        if kind is int and isinstance(value, bool):
            raise TypeError
        return kind(value)
    except (TypeError, ValueError) as exc:
        raise ConfigError(
            f'parameter {name!r} must be a finite {kind.__name__}, got {value!r}') from exc


def section(params: Mapping[str, ParamValue], prefix: str) -> dict[str, ParamValue]:
    """Return the parameters under ``prefix.`` with the prefix stripped."""
    cut = prefix.rstrip('.') + '.'
    return {k[len(cut):]: v for k, v in params.items() if k.startswith(cut)}


_KINDS = {'float': float, 'int': int, 'str': str, 'bool': bool}


def build_settings(cls: type, params: Mapping[str, ParamValue], prefix: str):
    """Build settings dataclass ``cls`` from the dotted parameters ``<prefix>.<field>``.

    Each field's annotation (float, int, str, bool) gives the conversion; a
    missing or ill-typed value raises ConfigError naming ``<prefix>.<field>``.
    """
    values = {}
    for f in fields(cls):
        name = f'{prefix}.{f.name}'
        kind = _KINDS[f.type if isinstance(f.type, str) else f.type.__name__]
        if kind is bool:
            if not isinstance(params.get(name), bool):
                raise ConfigError(f'parameter {name!r} must be true or false')
            values[f.name] = params[name]
        else:
            values[f.name] = require(params, name, kind)
    return cls(**values)
