# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
"""The configuration of every stage from a YAML file of config/ and keys given in Python."""
import json
import re

from ._core import Config, ConfigError


def load_config(path=None, overrides=None):
    """A Config: the defaults in code, the sections of the YAML file `path` (config/kitti.yaml
    lists every key) over them, and `overrides` over both, as {"section": {"key": value}} or
    {"section.key": value}:

        msfusion.load_config(overrides={"tsdf_volume.voxel_size_m": 0.2, "tsdf_integrator": {"lambda": 5.0}})

    The library reads the result as it reads a file, so a key it does not know, a wrong type
    (a str is a YAML string: "0.2" is not the number 0.2) or a value out of range is a
    ConfigError that names it."""
    config = Config.load(path) if path else Config()
    if not overrides:
        return config
    sections = _sections(config.yaml())
    for key, value in overrides.items():
        if isinstance(value, dict):
            for name, item in value.items():
                sections.setdefault(key, {})[name] = _yaml_value(item)
        else:
            section, dot, name = key.partition(".")
            if not dot or not name:
                raise ValueError(f"override '{key}' must be 'section.key' or a section's dict of keys")
            sections.setdefault(section, {})[name] = _yaml_value(value)
    try:
        return Config.from_yaml(_yaml_text(sections), "overrides")
    except ConfigError as error:  # the overrides are not a file: no line to point at
        raise ConfigError(re.sub(r"^config 'overrides' line \d+: ", "overrides: ", str(error))) from None


def _sections(text):
    """Config.yaml()'s text as {section: {key: value text}}: a section's name at column 0, its
    keys indented, one a line."""
    sections, current = {}, None
    for line in text.splitlines():
        if not line.strip() or line.startswith("%") or line.lstrip().startswith("#"):
            continue
        name, _, value = line.strip().partition(":")
        if not line[0].isspace():
            current = sections.setdefault(name, {})
        elif current is not None:
            current[name] = value.strip()
    return sections


def _yaml_value(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_yaml_value(v) for v in value) + "]"
    if isinstance(value, str):  # quoted, as YAML writes a string: "0.2" is not the number 0.2
        return json.dumps(value)
    return str(value)


def _yaml_text(sections):
    lines = []
    for section, keys in sections.items():
        lines.append(f"{section}:")
        lines.extend(f"  {name}: {value}" for name, value in keys.items())
    return "\n".join(lines) + "\n"

