"""The controllers YAML: a ros2_control controllers file read into a :class:`ControllersConfig`.

:func:`load_controllers_yaml` reads a controllers file in the ros2_control layout::

    controller_manager:
      ros__parameters:
        update_rate: 100
        joint_state_broadcaster:
          type: joint_state_broadcaster/JointStateBroadcaster
    joint_state_broadcaster:
      ros__parameters: {}

It is read as ROS 2 Jazzy reads a parameter file, for the nodes of one namespace (``"/"`` unless given):

* node keys are matched to each node's fully qualified name as rclcpp matches them (:func:`node_key_matches`):
  ``/rrbot_1/controller_manager`` there only, a key without a leading ``/`` in the root namespace only, ``/*`` one
  namespace part, ``/**`` any number; every matching section gives its parameters in file order, a later one winning;
* lists of maps are read as rcl_yaml_param_parser reads them (:func:`rcl_parameters`);
* with launch arguments, ``$(var name)`` is filled first, as launch's ``ParameterFile(allow_substs=True)`` does;
* a parameter file given at load (the spawner's ``--param-file``) is found for a controller as Jazzy's spawner finds
  it (:meth:`ControllersConfig.use_param_file`).

The declared parameters of each controller type, and their validation, are in
:mod:`rrbot_workshop.middleware.params`, which also offers both names of this module.
"""

from __future__ import annotations

import copy
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware.text_files import load_yaml, read_text

__all__ = ["ControllersConfig", "load_controllers_yaml", "rcl_parameters", "node_key_matches", "fully_qualified",
           "normalize_namespace", "MANAGER_NODE"]


#: The node name of the controller manager (``ros2_control_node`` starts it as ``controller_manager``).
MANAGER_NODE = "controller_manager"


def normalize_namespace(namespace: str | None) -> str:
    """A node namespace as ROS writes it: ``"/"`` or ``"/a/b"`` (a leading ``/`` added, a trailing one dropped).

    Raises:
        ParameterError: If a part is not a valid name (letters, digits, underscores, not starting with a digit).
    """
    ns = "/" + str(namespace or "").strip().strip("/")
    for part in ns.strip("/").split("/") if ns != "/" else []:
        if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", part):
            raise ParameterError("bringup", "namespace", f"{namespace!r} is not a valid node namespace: the part "
                                 f"{part!r} must be letters, digits and underscores, not starting with a digit "
                                 "(e.g. '/rrbot_1')")
    return ns


def fully_qualified(namespace: str, name: str) -> str:
    """``/<namespace>/<name>`` (``/<name>`` in the root namespace)."""
    ns = normalize_namespace(namespace)
    return f"/{name}" if ns == "/" else f"{ns}/{name}"


def node_key_matches(key: str, fqn: str) -> bool:
    """Whether a parameter file's node key applies to the node ``fqn``, as rclcpp decides it.

    The key gets a leading ``/`` if it has none (so ``controller_manager`` is ``/controller_manager``: the root
    namespace only), ``/*`` stands for one namespace part and ``/**`` for any number of them (none included).
    """
    full = key if key.startswith("/") else "/" + key
    pattern = re.escape(full).replace(re.escape("/*"), r"(/\w+)").replace(r"\*", "*")
    return re.fullmatch(pattern, fqn) is not None


def _deep_merge(base: dict[str, Any], extra: Mapping[str, Any]) -> None:
    """Merge ``extra`` into ``base``: a later file's value wins parameter by parameter (lists are replaced)."""
    for key, value in extra.items():
        if isinstance(value, Mapping) and value and isinstance(base.get(key), dict):
            _deep_merge(base[key], value)
        else:
            base[key] = copy.deepcopy(value)


@dataclass
class ControllersConfig:
    """Content of a controllers YAML file, as the nodes of one namespace read it.

    Attributes:
        update_rate: Controller manager rate in [Hz] (default 100, as in ros2_control).
        manager_parameters: Every ``controller_manager`` parameter that is not a controller entry.
        controller_types: Controller name -> type string, from ``controller_manager.ros__parameters``.
        controller_parameters: Controller name -> its ``ros__parameters`` (nested dict); a key with a wildcard
            (``/**``, ``/**/fwd``, ``/*/fwd``) is kept as written and applies to every controller it matches.
        source: File path or ``"<string>"``.
        namespace: The namespace of the controller manager and its controllers (``"/"``, ``"/rrbot_1"``).
        sections: Every node section of the file in the order of first appearance: (node key with a leading
            ``/``, its ``ros__parameters``), lists of maps read as rcl reads them.
    """

    update_rate: int = 100
    manager_parameters: dict[str, Any] = field(default_factory=dict)
    controller_types: dict[str, str] = field(default_factory=dict)
    controller_parameters: dict[str, dict[str, Any]] = field(default_factory=dict)
    source: str = "<string>"
    namespace: str = "/"
    sections: list[tuple[str, dict[str, Any]]] = field(default_factory=list)
    param_files: dict[str, list[str]] = field(default_factory=dict)
    param_file_parameters: dict[str, dict[str, Any]] = field(default_factory=dict)
    #: Controller name -> the manager's ``<name>.params_file`` as the file writes it (a string or a list).
    manager_params_files: dict[str, Any] = field(default_factory=dict)

    def params_files_of(self, name: str) -> list[str]:
        """The files of the manager's ``<name>.params_file`` parameter (Jazzy's ``load_controller`` reads it), in
        order; empty if it is not set.

        Raises:
            ParameterError: If the value is neither a string nor a list of strings.
        """
        value = self.manager_params_files.get(name)
        if value is None:
            return []
        if isinstance(value, str):
            return [value]
        if isinstance(value, list) and value and all(isinstance(v, str) for v in value):
            return list(value)
        raise ParameterError("controller_manager", f"{name}.params_file", f"must be a string or a list of strings "
                             f"(paths of parameter files with a section for '{name}'), got {value!r} ({self.source})")

    def parameters_for(self, name: str) -> dict[str, Any]:
        """Parameters of controller ``name`` (a deep copy; empty if none were given).

        Every section whose node key matches the controller's fully qualified name (``<namespace>/<name>``) gives
        its parameters, in file order, a later one winning parameter by parameter, as rclcpp merges them. The
        parameter files given for it at load (:meth:`use_param_file`, the spawner's ``--param-file``) come last and
        win, as the files a controller node is started with override the global ones.
        """
        fqn = fully_qualified(self.namespace, name)
        merged: dict[str, Any] = {}
        for key, params in self.controller_parameters.items():
            if key == name or ("*" in key and node_key_matches(key, fqn)):
                _deep_merge(merged, params)
        _deep_merge(merged, self.param_file_parameters.get(name, {}))
        return merged

    def use_param_file(self, name: str, source: str | Path, launch_args: Mapping[str, Any] | None = None) -> bool:
        """Give controller ``name`` a parameter file, as the spawner's ``--param-file`` (and ``ros2 control
        load_controller NAME FILE``) does before the load.

        As Jazzy's spawner: the file counts for the controller when it has a section ``<name>``, ``/<ns>/<name>``,
        ``/**/<name>`` or ``/**/<ns>/<name>``, ``<name>`` inside ``/**``, or a ``/**`` section of its own. Then its
        ``type`` (first of those sections that has one) becomes the controller's type, and the controller reads the
        whole file as its node would (:func:`node_key_matches`), over the controllers YAML.

        Args:
            name: Controller name.
            source: The parameter file.
            launch_args: Values for ``$(var name)`` in the file, as for a file handed to the spawner as
                ``ParameterFile(..., allow_substs=True)``; None reads the file as it is.

        Returns:
            Whether the file has parameters for the controller (if not, nothing changes and it is not used).

        Raises:
            ParameterError: If the file cannot be read, a substitution fails, the file is not a parameter file, or it
                names the controller without its namespace while the controller is in one (the spawner stops there).
        """
        from rrbot_workshop.middleware.param_substitution import substitute

        path = Path(source)
        text, problem = read_text(path)
        if problem:
            raise ParameterError("parameter file", str(path), problem)
        if launch_args is not None and "$(" in text:
            text = substitute(text, launch_args, source=str(path))
        data, problem = load_yaml(text)
        if problem:
            raise ParameterError("parameter file", str(path), problem)
        if not isinstance(data, Mapping):
            raise ParameterError("parameter file", str(path), "must be a mapping of node names to 'ros__parameters'")
        ns = self.namespace
        fqn = fully_qualified(ns, name)
        wild = data.get("/**")
        found: list[Any] = []
        for key in (name, fqn, f"/**/{name}", f"/**{fqn}"):
            if key in data:
                if key == name and ns != "/":
                    raise ParameterError("parameter file", str(path), f"names '{name}' without a namespace, but the "
                                         f"controller is {fqn}: write '{fqn}:' or '/**/{name}:' (Jazzy's spawner stops "
                                         "here)")
                found.append(data[key])
            elif isinstance(wild, Mapping) and key in wild:
                found.append(wild[key])
            elif isinstance(wild, Mapping) and "ros__parameters" in wild:
                found.append(wild)
        if not found:
            return False
        for section in found:
            if not isinstance(section, Mapping) or not isinstance(section.get("ros__parameters"), Mapping | None):
                raise ParameterError("parameter file", str(path), f"is not a valid ROS parameter file for {fqn}: its "
                                     "section needs 'ros__parameters:'")
        ctype = next((sec["ros__parameters"]["type"] for sec in found
                      if isinstance(sec.get("ros__parameters"), Mapping) and "type" in sec["ros__parameters"]), None)
        file_cfg = _configure(_node_sections(data, str(path)), str(path), ns)
        params = file_cfg.parameters_for(name)
        if ctype is not None:
            if not isinstance(ctype, str) or "/" not in ctype:
                raise ParameterError(name, "type", f"'{ctype}' in {path} is not a plugin type string such as "
                                     "'package/ClassName'")
            self.controller_types[name] = ctype
        self.param_files.setdefault(name, []).append(str(path))
        _deep_merge(self.param_file_parameters.setdefault(name, {}), params)
        return True

    def section_names(self) -> dict[str, str]:
        """Controller name -> the node key it is written under, for every controller section that reaches a node of
        this namespace: a plain key, or a wildcard key ending in a name (``/**/fwd`` -> ``fwd``). ``/**`` itself and
        keys ending in a wildcard name no controller and are left out."""
        out: dict[str, str] = {}
        for key in self.controller_parameters:
            last = key.rsplit("/", 1)[-1]
            if "*" in last:
                continue
            if key == last or node_key_matches(key, fully_qualified(self.namespace, last)):
                out.setdefault(last, key)
        return out

    @property
    def manager_name(self) -> str:
        """The fully qualified name of the controller manager (``/controller_manager``, ``/rrbot_1/controller_manager``)."""
        return fully_qualified(self.namespace, MANAGER_NODE)

    def manager_namespaces(self) -> list[str]:
        """Namespaces for which the file configures a controller manager by an explicit key (no wildcard)."""
        out = []
        for key, _ in self.sections:
            if "*" not in key and key.rsplit("/", 1)[-1] == MANAGER_NODE:
                ns = key.rsplit("/", 1)[0] or "/"
                if ns not in out:
                    out.append(ns)
        return out

    def for_namespace(self, namespace: str) -> ControllersConfig:
        """The same file as the nodes of ``namespace`` read it (a new config; this one is unchanged).

        A config built by hand (without sections) keeps its entries and only changes its namespace.

        Raises:
            ParameterError: If the namespace is not valid.
        """
        ns = normalize_namespace(namespace)
        if not self.sections:
            out = copy.deepcopy(self)
            out.namespace = ns
            return out
        return _configure(self.sections, self.source, ns)


def _node_sections(data: Mapping[str, Any], where: str) -> list[tuple[str, dict[str, Any]]]:
    """(node key, ros__parameters) of every node in the file, keys joined as rcl joins nested namespace keys."""
    sections: dict[str, dict[str, Any]] = {}

    def walk(prefix: str, node: Mapping[str, Any], shown: str) -> None:
        for raw_key, body in node.items():
            key = str(raw_key)
            full = key if not prefix else prefix + ("" if prefix.endswith("/") else "/") + key
            label = f"{shown}.{raw_key}" if shown else str(raw_key)
            if isinstance(body, Mapping) and "ros__parameters" in body:
                params = body["ros__parameters"] or {}
                if not isinstance(params, Mapping):
                    raise ParameterError("controllers file", f"{where}: {label}.ros__parameters", "must be a mapping")
                name = full if full.startswith("/") else "/" + full
                flat = rcl_parameters(params, f"{where}: {label}")
                _deep_merge(sections.setdefault(name, {}), flat)
            elif isinstance(body, Mapping) and body and all(isinstance(v, Mapping) for v in body.values()):
                walk(full, body, label)  # a namespace key: 'rrbot_1: {controller_manager: {ros__parameters: ...}}'
            else:
                raise ParameterError(
                    "controllers file", f"{where}: {label}", "each node entry needs a 'ros__parameters:' mapping"
                )

    walk("", data, "")
    return list(sections.items())


def _configure(sections: list[tuple[str, dict[str, Any]]], where: str, namespace: str) -> ControllersConfig:
    """The config of the nodes in ``namespace`` from the file's sections."""
    cfg = ControllersConfig(source=where, namespace=namespace, sections=copy.deepcopy(sections))
    manager_fqn = fully_qualified(namespace, MANAGER_NODE)
    wildcard_types: dict[str, str] = {}
    for key, params in sections:
        last = key.rsplit("/", 1)[-1]
        if key == "/**":
            # '/**' reaches every node, the controller manager too: '<name>: {type: ...}' there declares a
            # controller (unless the controller_manager section declares it itself); the rest goes to every controller
            shared = {}
            for pname, pval in params.items():
                ctype = pval.get("type") if isinstance(pval, Mapping) else None
                if isinstance(ctype, str) and "/" in ctype:
                    wildcard_types.setdefault(str(pname), ctype)
                else:
                    shared[pname] = pval
            _deep_merge(cfg.controller_parameters.setdefault(key, {}), shared)
        elif last == MANAGER_NODE:
            if node_key_matches(key, manager_fqn):
                _manager_section(cfg, params, where)
        elif "*" in key:
            _deep_merge(cfg.controller_parameters.setdefault(key, {}), params)
        else:
            ns = key.rsplit("/", 1)[0] or "/"
            if ns == namespace:
                _deep_merge(cfg.controller_parameters.setdefault(last, {}), params)
    for pname, ctype in wildcard_types.items():
        cfg.controller_types.setdefault(pname, ctype)
    rate = cfg.manager_parameters.get("update_rate", 100)
    if not isinstance(rate, int) or isinstance(rate, bool) or rate <= 0:
        raise ParameterError("controller_manager", "update_rate", f"must be a positive integer [Hz], got {rate!r}")
    cfg.update_rate = rate
    return cfg


def _manager_section(cfg: ControllersConfig, params: Mapping[str, Any], where: str) -> None:
    for pname, pval in params.items():
        if isinstance(pval, Mapping) and "params_file" in pval:  # the manager's <name>.params_file, not the controller's
            cfg.manager_params_files[str(pname)] = copy.deepcopy(pval["params_file"])
            pval = {k: v for k, v in pval.items() if k != "params_file"}
            if not pval:
                continue
        elif str(pname).endswith(".params_file") and str(pname) != ".params_file":
            cfg.manager_params_files[str(pname)[: -len(".params_file")]] = copy.deepcopy(pval)
            continue
        if isinstance(pval, Mapping) and "type" in pval:
            ctype = pval["type"]
            if not isinstance(ctype, str) or "/" not in ctype:
                raise ParameterError(
                    "controller_manager",
                    f"{pname}.type",
                    f"'{ctype}' is not a plugin type string such as 'package/ClassName' ({where})",
                )
            cfg.controller_types[str(pname)] = ctype
            extra = {k: v for k, v in pval.items() if k != "type"}
            if extra:
                _deep_merge(cfg.controller_parameters.setdefault(str(pname), {}), extra)
        elif isinstance(pval, Mapping) and isinstance(cfg.manager_parameters.get(pname), dict):
            _deep_merge(cfg.manager_parameters[pname], pval)
        else:
            cfg.manager_parameters[str(pname)] = copy.deepcopy(pval)


def load_controllers_yaml(source: str | Path | Mapping[str, Any], namespace: str = "/",
                          launch_args: Mapping[str, Any] | None = None) -> ControllersConfig:
    """Read a controllers file (path, YAML text, or an already-parsed mapping) for the nodes of ``namespace``.

    With ``launch_args`` (even empty) the text is read as launch's ``ParameterFile(path, allow_substs=True)`` reads
    it: ``$(var name)`` becomes the launch argument (see :mod:`~rrbot_workshop.middleware.param_substitution`); a
    variable that is not given is a :class:`ParameterError` naming the file, the line and the variable. Without, the
    text is read as it is (as rcl reads a file given with ``--params-file``).

    Node keys are matched as ROS 2 matches them (:func:`node_key_matches`): ``/rrbot_1/controller_manager`` only in
    ``/rrbot_1``, ``controller_manager`` only in the root namespace, ``/**/controller_manager`` in every namespace.
    Lists of maps are read as rcl's parser reads them (:func:`rcl_parameters`).

    Raises:
        ParameterError: If the YAML is malformed or does not follow the ros2_control layout.
    """
    where = "<string>"
    if isinstance(source, Mapping):
        data: Any = source
    elif not isinstance(source, str | Path):
        raise ParameterError("controllers file", repr(source)[:80], f"must be a path, YAML text or a mapping, not "
                                                                  f"{type(source).__name__}")
    else:
        text = str(source)
        if isinstance(source, Path) or (("\n" not in text) and text.endswith((".yaml", ".yml"))):
            path = Path(source)
            where = str(path)
            text, problem = read_text(path)
            if problem:
                raise ParameterError("controllers file", where, problem)
        if launch_args is not None and "$(" in text:
            from rrbot_workshop.middleware.param_substitution import substitute

            text = substitute(text, launch_args, source=where)
        data, problem = load_yaml(text)
        if problem:
            raise ParameterError("controllers file", where, problem)
        if data is None:
            raise ParameterError("controllers file", where, "is empty; it needs a 'controller_manager:' entry with "
                                 "'ros__parameters:' (update_rate and the controllers' types)")
    if not isinstance(data, Mapping):
        raise ParameterError("controllers file", where, "must be a mapping of node names to 'ros__parameters'")
    return _configure(_node_sections(data, where), where, normalize_namespace(namespace))


# ---------------------------------------------------------------------------------------------------------
# rcl_yaml_param_parser's reading of a node's parameters


class _RclParams:
    """rcl_yaml_param_parser's state machine over the events of one node's ``ros__parameters`` mapping.

    rcl reads a parameter file event by event: a key under a key becomes a dotted name (``gains.joint1.p``), and a
    sequence holds scalars. A mapping inside a sequence is not refused: its keys continue the dotted name of the
    parameter that holds the sequence, and its scalar values are appended to that parameter's array. So

    .. code-block:: yaml

        command_interfaces:
          flange_vacuum:
            - interfaces: [vacuum]

    gives ``command_interfaces.flange_vacuum.interfaces = [vacuum]``, as if the ``-`` were not there. The
    bookkeeping below (a parameter namespace string with a count; the current parameter renamed as its name grows)
    follows rcl's ``parse_file_events``/``parse_key``/``parse_value`` and ``namespace.c``.
    """

    def __init__(self, where: str) -> None:
        self.where = where
        self.names: list[str] = []
        self.values: list[Any] = []
        self.ns: str | None = None
        self.ns_count = 0
        self.idx = 0
        self.is_key = True
        self.is_seq = False
        self.is_new_map = False
        self.seq_type: type | None = None

    def _find(self, name: str) -> int:
        if name in self.names:
            return self.names.index(name)
        self.names.append(name)
        self.values.append(_UNSET)
        return len(self.names) - 1

    def key(self, name: str) -> None:
        if self.is_new_map:
            self.ns, self.ns_count = self.names[self.idx], self.ns_count + 1
            self.is_new_map = False
        if self.ns is None:
            self.idx = self._find(name)
        else:
            self.idx = self._find(self.ns)
            self.names[self.idx] = f"{self.ns}.{name}"

    def value(self, value: Any) -> None:
        if not self.is_seq:
            self.values[self.idx] = value
            return
        kind = float if isinstance(value, float) else type(value)
        if self.seq_type is None:
            self.seq_type = kind
            self.values[self.idx] = [value]
            return
        if kind is not self.seq_type:
            raise ParameterError(self.where, self.names[self.idx], f"a sequence holds values of one type; {value!r} "
                                 f"({kind.__name__}) follows values of type {self.seq_type.__name__}")
        current = self.values[self.idx]
        self.values[self.idx] = ([*current, value] if isinstance(current, list) else [value])

    def remove_ns(self) -> bool:
        """Leave a mapping: drop the last part of the parameter namespace; False when there was none."""
        if self.ns_count == 0:
            return False
        if self.ns_count == 1:
            self.ns = None
        elif self.ns is not None and "." in self.ns:
            self.ns = self.ns.rsplit(".", 1)[0]
        self.ns_count -= 1
        return True

    def node(self, item: Any, top: bool = False) -> None:
        if isinstance(item, Mapping):
            self.is_new_map = not top
            self.is_key = True
            for k, v in item.items():
                self.scalar(str(k))
                if isinstance(v, Mapping | list) and not v:
                    self.value(copy.deepcopy(v))  # an empty mapping or list: kept as a value, as the library reads it
                    self.is_key = True
                else:
                    self.node(v)
            if not top:
                self.remove_ns()
        elif isinstance(item, list):
            if self.is_key:
                name = self.names[self.idx] if self.names else "?"
                raise ParameterError(self.where, name, "a sequence inside a sequence is not a ROS parameter value "
                                     "(rcl: 'Sequences cannot be key'); write one flat list")
            self.is_seq = True
            self.seq_type = None
            for entry in item:
                self.node(entry)
            self.is_seq = False
            self.is_key = True
        else:
            self.scalar(item)

    def scalar(self, item: Any) -> None:
        if self.is_key:
            self.key(str(item))
            self.is_key = False
        else:
            if item is None:
                raise ParameterError(self.where, self.names[self.idx], "has no value (rcl: 'No value'); give one")
            self.value(item)
            if not self.is_seq:
                self.is_key = True


_UNSET: Any = object()


def _has_map_in_list(value: Any) -> bool:
    if isinstance(value, list):
        return any(isinstance(v, Mapping) or _has_map_in_list(v) for v in value)
    if isinstance(value, Mapping):
        return any(_has_map_in_list(v) for v in value.values())
    return False


def rcl_parameters(params: Mapping[str, Any], where: str = "<parameters>") -> dict[str, Any]:
    """A node's ``ros__parameters`` as rcl's YAML parser reads them, nested again by the dots of the names.

    Parameters without a list of maps are kept as they are. A parameter whose value holds a list of maps is read by
    rcl's state machine (:class:`_RclParams`): the list of maps is flattened, e.g. ``flange: [{interfaces: [a]}]``
    becomes ``flange.interfaces = [a]``.

    Raises:
        ParameterError: Where rcl refuses the value (a list of lists, a list mixing types inside such a value).
    """
    out: dict[str, Any] = {}
    for key, value in params.items():
        if not _has_map_in_list(value):
            out[key] = copy.deepcopy(value)
            continue
        machine = _RclParams(where)
        machine.node({key: value}, top=True)
        for name, val in zip(machine.names, machine.values, strict=True):
            if val is _UNSET:
                continue
            _place_dotted(out, name, val)
    return out


def _place_dotted(root: dict[str, Any], dotted: str, value: Any) -> None:
    """Put ``value`` at ``a.b.c`` in nested dicts; where a value already sits on the path, keep the dotted name."""
    parts = dotted.split(".")
    node = root
    for i, part in enumerate(parts[:-1]):
        nxt = node.get(part)
        if nxt is None:
            nxt = node[part] = {}
        if not isinstance(nxt, dict):
            node[".".join(parts[i:])] = value
            return
        node = nxt
    node[parts[-1]] = value
