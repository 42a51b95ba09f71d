"""Parameters: the parameters a controller declares, and their validated values.

:class:`ParameterSchema` plays the role of generate_parameter_library: a controller declares its
parameters in the same YAML syntax (``type``, ``default_value``, ``read_only``, ``validation`` with
``not_empty<>``, ``one_of<>``, ``gt<>``, ..., ``__map_<list>`` for per-joint entries), and
:class:`ParamListener` turns the values given for one controller into a validated, read-only
parameter object. Errors name the controller and the parameter and say what would be valid.

The controllers YAML that gives those values is read by :mod:`rrbot_workshop.middleware.controllers_yaml`;
its :class:`ControllersConfig` and :func:`load_controllers_yaml` are importable from here too.
"""

from __future__ import annotations

import copy
import functools
import logging
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import yaml

from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware.controllers_yaml import ControllersConfig, load_controllers_yaml

__all__ = [
    "ControllersConfig",
    "load_controllers_yaml",
    "ParameterSchema",
    "ParamListener",
    "Params",
    "register_validator",
    "flatten",
]

_log = logging.getLogger(__name__)

# ---------------------------------------------------------------------------------------------------------
# schemas (generate_parameter_library equivalent)

_TYPES: dict[str, tuple[type, ...]] = {
    "bool": (bool,),
    "int": (int,),
    "double": (float, int),
    "string": (str,),
    "bool_array": (bool,),
    "int_array": (int,),
    "double_array": (float, int),
    "string_array": (str,),
}

Validator = Callable[..., "str | None"]
_CUSTOM_VALIDATORS: dict[str, Validator] = {}


def register_validator(name: str, fn: Validator) -> None:
    """Register a custom validator usable in a schema as ``validation: {<name>: [args]}``.

    ``fn(value, *args)`` returns None when the value is valid, else a sentence saying why not.
    """
    _CUSTOM_VALIDATORS[name] = fn


def _builtin_validator(name: str, value: Any, args: list[Any]) -> str | None:  # noqa: PLR0911, C901
    n = name.removesuffix("<>")
    seq = value if isinstance(value, list) else None
    if n == "not_empty":
        return "must not be empty" if (value == "" or value == []) else None
    if n == "unique":
        dup = sorted({v for v in seq or [] if (seq or []).count(v) > 1})
        return f"must have unique entries, but {dup} repeat" if dup else None
    if n == "one_of":
        choices = args[0] if args else []
        return None if value in choices else f"must be one of {choices}, got {value!r}"
    if n == "subset_of":
        choices = args[0] if args else []
        bad = [v for v in seq or [] if v not in choices]
        return f"entries must be among {choices}, but {bad} are not" if bad else None
    if n in ("gt", "gt_eq", "lt", "lt_eq", "bounds", "element_bounds", "lower_element_bounds", "upper_element_bounds"):
        items = seq if seq is not None else [value]
        for v in items:
            if n == "gt" and not v > args[0]:
                return f"must be > {args[0]}, got {v}"
            if n in ("gt_eq", "lower_element_bounds") and not v >= args[0]:
                return f"must be >= {args[0]}, got {v}"
            if n == "lt" and not v < args[0]:
                return f"must be < {args[0]}, got {v}"
            if n in ("lt_eq", "upper_element_bounds") and not v <= args[0]:
                return f"must be <= {args[0]}, got {v}"
            if n in ("bounds", "element_bounds") and not args[0] <= v <= args[1]:
                return f"must be within [{args[0]}, {args[1]}], got {v}"
        return None
    if n in ("size_gt", "size_lt", "fixed_size"):
        size = len(value)
        if n == "size_gt" and not size > args[0]:
            return f"must have more than {args[0]} entries, got {size}"
        if n == "size_lt" and not size < args[0]:
            return f"must have fewer than {args[0]} entries, got {size}"
        if n == "fixed_size" and size != args[0]:
            return f"must have exactly {args[0]} entries, got {size}"
        return None
    fn = _CUSTOM_VALIDATORS.get(name) or _CUSTOM_VALIDATORS.get(n) or _CUSTOM_VALIDATORS.get(n.split("::")[-1])
    if fn is None:
        raise KeyError(name)
    return fn(value, *args)


@dataclass
class _Decl:
    path: tuple[str, ...]  # may contain "__map_<list>" parts
    type: str
    default: Any
    read_only: bool
    validation: dict[str, list[Any]]
    description: str


@functools.lru_cache(maxsize=128)
def _parsed_once(text: str) -> Any:
    return yaml.safe_load(text)


def _parsed(text: str) -> Any:
    """A schema's YAML, parsed once per text (every load of a controller type declares the same schema)."""
    return copy.deepcopy(_parsed_once(text))


class ParameterSchema:
    """Declared parameters of one controller type, in generate_parameter_library's YAML syntax.

    Args:
        definition: YAML text or mapping, ``{<namespace>: {<param>: {type: ..., ...}, ...}}``.
    """

    def __init__(self, definition: str | Mapping[str, Any]) -> None:
        data = _parsed(definition) if isinstance(definition, str) else definition
        if not isinstance(data, Mapping) or len(data) != 1:
            raise ParameterError("schema", "<root>", "must be a mapping with exactly one namespace key")
        self.namespace: str = str(next(iter(data)))
        self.declarations: list[_Decl] = []
        self._walk(data[self.namespace] or {}, ())

    def _walk(self, node: Mapping[str, Any], path: tuple[str, ...]) -> None:
        for key, val in node.items():
            if isinstance(val, Mapping) and "type" in val and not isinstance(val["type"], Mapping):
                ptype = str(val["type"])
                if ptype not in _TYPES:
                    raise ParameterError("schema", ".".join((*path, key)), f"unknown type '{ptype}' (valid: {list(_TYPES)})")
                default = val.get("default_value")
                if default is None:
                    default = [] if ptype.endswith("_array") else None
                self.declarations.append(
                    _Decl(
                        (*path, str(key)),
                        ptype,
                        default,
                        bool(val.get("read_only", False)),
                        {str(k): list(v or []) for k, v in (val.get("validation") or {}).items()},
                        str(val.get("description", "")),
                    )
                )
            elif isinstance(val, Mapping):
                self._walk(val, (*path, str(key)))
            else:
                raise ParameterError("schema", ".".join((*path, str(key))), "needs a 'type' entry")

    def merged(self, other: ParameterSchema) -> ParameterSchema:
        """A schema with the declarations of both (``other`` wins on the same name)."""
        out = copy.copy(self)
        names = {d.path for d in other.declarations}
        out.declarations = [d for d in self.declarations if d.path not in names] + list(other.declarations)
        return out

    def describe(self) -> list[tuple[str, str, Any, str]]:
        """``(name, type, default, description)`` for each declared parameter, for documentation."""
        return [(".".join(d.path), d.type, d.default, d.description) for d in self.declarations]


def flatten(values: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """Nested mapping -> dotted names: ``{"gains": {"j1": {"p": 1}}}`` -> ``{"gains.j1.p": 1}``."""
    out: dict[str, Any] = {}
    for key, val in values.items():
        name = f"{prefix}{key}"
        if isinstance(val, Mapping) and val:
            out.update(flatten(val, name + "."))
        else:
            out[name] = val
    return out


class Params:
    """Read-only parameter values; nested groups are attributes, mapped groups are ``<list>_map`` dicts."""

    def __init__(self, values: Mapping[str, Any]) -> None:
        object.__setattr__(self, "_values", dict(values))
        # plain attributes: a controller's cycle reads its parameters at the cost of any attribute; only a missing
        # name reaches __getattr__ (and its message); a parameter named like a method stays reachable by [name]
        cls = type(self)
        self.__dict__.update((k, v) for k, v in self._values.items() if k.isidentifier() and not hasattr(cls, k))

    def __getattr__(self, name: str) -> Any:
        try:
            return self._values[name]
        except KeyError:
            raise AttributeError(f"no parameter '{name}' (have: {', '.join(sorted(self._values))})") from None

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError(f"parameters are read-only; cannot set '{name}'")

    def __getitem__(self, name: str) -> Any:
        return self._values[name]

    def __contains__(self, name: str) -> bool:
        return name in self._values

    def as_dict(self) -> dict[str, Any]:
        """Nested plain-dict copy."""
        return {k: (v.as_dict() if isinstance(v, Params) else
                    {kk: vv.as_dict() for kk, vv in v.items()} if isinstance(v, dict) else v)
                for k, v in self._values.items()}

    def __repr__(self) -> str:
        return f"Params({self.as_dict()!r})"


def _coerce(owner: str, name: str, ptype: str, value: Any) -> Any:
    allowed = _TYPES[ptype]
    if ptype.endswith("_array"):
        if not isinstance(value, list):
            raise ParameterError(owner, name, f"must be a list of {ptype[:-6]}, got {value!r}")
        items = value
    else:
        items = [value]
    out = []
    for v in items:
        if isinstance(v, bool) and bool not in allowed:
            raise ParameterError(owner, name, f"must be of type {ptype}, got the bool {v!r}")
        if not isinstance(v, allowed):
            raise ParameterError(owner, name, f"must be of type {ptype}, got {type(v).__name__} {v!r}")
        out.append(float(v) if float in allowed else v)  # type: ignore[arg-type]
    return out if ptype.endswith("_array") else out[0]


class ParamListener:
    """Validated parameters of one controller.

    Args:
        schema: The controller type's declarations.
        values: The values given for this controller (nested as in YAML, or dotted names).
        owner: Controller name, used in error messages.

    Raises:
        ParameterError: If a value has the wrong type or fails a validator, or a parameter without a
            default is missing.
    """

    def __init__(self, schema: ParameterSchema, values: Mapping[str, Any], owner: str) -> None:
        self.schema = schema
        self.owner = owner
        self._source = values
        self._given = flatten(values)
        self._params = self._build()

    def get_params(self) -> Params:
        """The parameter values as of the last :meth:`refresh` (or construction)."""
        return self._params

    def refresh(self) -> Params:
        """Re-read and re-validate the values from the (live) source mapping.

        Raises:
            ParameterError: As the constructor.
        """
        self._given = flatten(self._source)
        self._params = self._build()
        return self._params

    @property
    def undeclared(self) -> list[str]:
        """Given names that no declaration uses (they are ignored, as ROS ignores undeclared overrides)."""
        return sorted(set(self._given) - self._used)

    def _build(self) -> Params:
        self._used: set[str] = set()
        self._expanded: set[str] = set()
        root: dict[str, Any] = {}
        for decl in self.schema.declarations:
            for name, value in self._expand(decl, root):
                self._place(root, name, value)
        self._check_groups()
        for given in self.undeclared:
            _log.warning("'%s' got parameter '%s', which it does not declare; it is ignored", self.owner, given)
        return self._to_params(root)

    def _check_groups(self) -> None:
        """A value given where the controller declares a group of parameters is refused: ignoring it would leave the
        group at its defaults (a controller that loads, activates and does nothing).

        Raises:
            ParameterError: Naming the controller, the parameter, what it holds and the names the group declares.
        """
        for given in self.undeclared:
            if isinstance(self._given[given], Mapping):  # an empty group ('gains: {}'): every entry at its default
                continue
            inside = sorted(n[len(given) + 1:] for n in self._expanded if n.startswith(given + "."))
            if inside:
                value = self._given[given]
                shown = repr(value) if len(repr(value)) <= 80 else repr(value)[:77] + "..."
                raise ParameterError(self.owner, given, f"is a group of parameters ({', '.join(inside)}), but the YAML "
                                     f"was given the value {shown}; give it as a mapping, e.g. "
                                     f"'{given.rsplit('.', 1)[-1]}: {{{inside[0]}: ...}}'")

    def _expand(self, decl: _Decl, root: dict[str, Any]) -> list[tuple[tuple[str, ...], Any]]:
        # Replace each "__map_<list>" segment by every entry of that list parameter.
        paths: list[tuple[tuple[str, ...], tuple[str, ...]]] = [((), ())]  # (actual path, storage path)
        for part in decl.path:
            if part.startswith("__map_"):
                list_name = part[len("__map_"):]
                entries = self._lookup_list(root, list_name)
                paths = [(a + (e,), s + (f"{list_name}_map", e)) for a, s in paths for e in entries]
            else:
                paths = [(a + (part,), s + (part,)) for a, s in paths]
        out = []
        for actual, storage in paths:
            name = ".".join(actual)
            self._expanded.add(name)
            value = self._given.get(name, None)
            if name in self._given:
                self._used.add(name)
            if value is None:
                if decl.default is None:
                    raise ParameterError(self.owner, name, f"is required ({decl.type}) and was not given")
                value = copy.deepcopy(decl.default)
            value = _coerce(self.owner, name, decl.type, value)
            for vname, args in decl.validation.items():
                try:
                    problem = _builtin_validator(vname, value, args)
                except KeyError:
                    raise ParameterError(self.owner, name, f"uses unknown validator '{vname}'") from None
                if problem:
                    raise ParameterError(self.owner, name, problem)
            out.append((storage, value))
        return out

    def _lookup_list(self, root: dict[str, Any], list_name: str) -> list[str]:
        node: Any = root
        for part in list_name.split("."):
            if not isinstance(node, dict) or part not in node:
                raise ParameterError(self.owner, list_name, "must be declared before the parameters mapped over it")
            node = node[part]
        return list(node)

    @staticmethod
    def _place(root: dict[str, Any], path: tuple[str, ...], value: Any) -> None:
        node = root
        for part in path[:-1]:
            node = node.setdefault(part, {})
        node[path[-1]] = value

    def _to_params(self, node: dict[str, Any]) -> Params:
        converted: dict[str, Any] = {}
        for key, val in node.items():
            if key.endswith("_map") and isinstance(val, dict):
                converted[key] = {k: self._to_params(v) for k, v in val.items()}
            elif isinstance(val, dict):
                converted[key] = self._to_params(val)
            else:
                converted[key] = val
        return Params(converted)


def is_nan(value: Any) -> bool:
    """True for a float NaN (helper for controllers)."""
    return isinstance(value, float) and math.isnan(value)
