"""What the launch runner (roc/launch/runner.py) tells roc about a launch file without starting its processes,
using the real launch library; imported only in the runner's process, like runner.py itself.

- ``explain``: the launch runs as ``ros2 launch`` would run it (arguments, substitutions, conditions,
  includes, groups, ``SetEnvironmentVariable``, launch_ros's parameter files and remappings), except that
  each process action stops where it would start its process (``ExecuteLocal.execute`` records the
  prepared command line, working directory and environment and returns), composable nodes are recorded,
  not loaded, a lifecycle node is not monitored, and timers fire a thousand times sooner (in the same
  order). Nothing joins the ROS graph. What starts only on a process's events (``OnProcessStart``,
  ``OnProcessExit``) is not seen.
- ``arguments``: the launch arguments of the file and of every file it includes, recursively, each with the
  file that declares it; include paths are evaluated with the arguments' values known so far (the
  command line's, then the defaults), which ros2 launch's ``--show-args`` does not do.
"""

from __future__ import annotations

import os
import tempfile
from typing import Any

# The methods replaced below are typed in launch_ros (mypy: method-assign) when the launch system is installed
# (scripts/setup.sh installs it from ../shared/oracles, when that is there) and Any when it is not; so their
# ignores also allow being unused, and mypy passes either way.


def _temporary_parameters(command: list[str]) -> dict[str, Any]:
    """The parameter files launch_ros wrote for this start (``launch_params_*``), read and removed: a real
    start writes its own."""
    import yaml

    found = {}
    for word in command:
        if os.path.basename(word).startswith("launch_params_") and os.path.dirname(word) == tempfile.gettempdir():
            try:
                with open(word) as handle:
                    found[word] = yaml.safe_load(handle)
                os.unlink(word)
            except OSError:
                pass
    return found


def _loads(action, context) -> list[dict[str, Any]]:
    """A LoadComposableNodes action's nodes, as it would ask its container to load them."""
    from launch_ros.actions.load_composable_nodes import get_composable_node_load_request
    from rclpy.parameter import parameter_value_to_python

    loads = []
    for description in action._LoadComposableNodes__composable_node_descriptions:
        request = get_composable_node_load_request(description, context)
        if request is not None:
            loads.append({"package": request.package_name, "plugin": request.plugin_name,
                          "node": request.node_name, "namespace": request.node_namespace or "/",
                          "remappings": list(request.remap_rules),
                          "parameters": {p.name: parameter_value_to_python(p.value) for p in request.parameters}})
    return loads


TIME_SCALE = 1e-3  # --explain's timers: a thousand times faster, in the same order


def _quick_timers() -> None:
    """TimerAction (and launch_ros's RosTimer, which would need the launch's ROS node) fire after a
    thousandth of their period: what they start is seen at once, in the order a start would see it."""
    import asyncio

    from launch.actions import TimerAction
    from launch.events import TimerEvent
    from launch.utilities.type_utils import perform_typed_substitution

    async def wait_to_fire_event(action, context) -> None:
        await asyncio.sleep(perform_typed_substitution(context, action.period, float) * TIME_SCALE)
        if not action._canceled_future.done():
            await context.emit_event(TimerEvent(timer_action=action))
        action._completed_future.set_result(None)

    TimerAction._wait_to_fire_event = wait_to_fire_event
    try:
        from launch_ros.actions import RosTimer

        RosTimer._wait_to_fire_event = wait_to_fire_event  # type: ignore[method-assign, unused-ignore]
    except ImportError:
        pass


def explain(path: str, arguments: list[tuple[str, str]], debug: bool) -> tuple[int, dict[str, Any]]:
    """Every process the launch would start: name, command line, working directory, environment."""
    import launch
    from launch.actions import ExecuteLocal, IncludeLaunchDescription
    from launch.launch_description_sources import AnyLaunchDescriptionSource
    from launch.utilities import perform_substitutions

    processes: list[dict[str, Any]] = []
    by_node: dict[str, dict[str, Any]] = {}

    def record(action, context):
        action.prepare(context)
        details = action.process_details
        command = [str(word) for word in details["cmd"]]
        entry = {"name": details["name"], "command": command, "cwd": details["cwd"] or os.getcwd(),
                 "env": dict(details["env"]), "respawn": bool(getattr(action, "_ExecuteLocal__respawn", False)),
                 "written_parameters": _temporary_parameters(command), "loads": []}
        processes.append(entry)
        try:
            by_node[action.node_name] = entry  # a launch_ros Node: a container may load nodes into it
        except (AttributeError, RuntimeError):
            pass
        return None

    ExecuteLocal.execute = record
    _quick_timers()
    try:
        from launch_ros.actions import ComposableNodeContainer, LifecycleNode, LoadComposableNodes, Node

        # a lifecycle node's state monitoring needs the launch's own ROS node: only its process is wanted
        LifecycleNode.execute = Node.execute  # type: ignore[method-assign, unused-ignore]

        def load(action, context):
            target = action._LoadComposableNodes__target_container
            name = (target.node_name if isinstance(target, ComposableNodeContainer)
                    else perform_substitutions(context, target))
            container = by_node.get(name)
            if container is None:  # loaded into a container this launch does not start
                container = {"name": name, "command": [], "cwd": "", "env": None, "respawn": False,
                             "written_parameters": {}, "loads": []}
                processes.append(container)
            container["loads"] += _loads(action, context)
            return None

        LoadComposableNodes.execute = load  # type: ignore[method-assign, unused-ignore]
    except ImportError:
        pass
    with tempfile.TemporaryDirectory(prefix="roc-explain-") as logs:
        launch.logging.launch_config.log_dir = logs
        service = launch.LaunchService(argv=[f"{name}:={value}" for name, value in arguments], noninteractive=True,
                                       debug=debug)
        service.include_launch_description(launch.LaunchDescription([IncludeLaunchDescription(
            AnyLaunchDescriptionSource(path), launch_arguments=arguments)]))
        code = service.run()
    return code, {"processes": processes}


def arguments(path: str, given: list[tuple[str, str]]) -> dict[str, Any]:
    """The launch arguments of ``path`` and the files it includes: name, description, default (as ros2
    launch describes it, and its value where known), declaring file, the includes that lead to it, whether a
    condition decides if it is used, and the value an include sets it to (which a value given on the
    command line does not override)."""
    from launch import LaunchContext
    from launch.actions import DeclareLaunchArgument, IncludeLaunchDescription, ResetLaunchConfigurations
    from launch.launch_description_sources import get_launch_description_from_any_launch_file
    from launch.utilities import normalize_to_list_of_substitutions, perform_substitutions

    context = LaunchContext()
    context.launch_configurations.update(dict(given))
    found: dict[str, dict[str, Any]] = {}
    unknown: list[str] = []

    def evaluate(substitutions) -> str | None:
        try:
            return perform_substitutions(context, normalize_to_list_of_substitutions(substitutions))
        except Exception:  # noqa: BLE001 - not knowable without running the launch
            return None

    def declare(argument, file: str, chain: list[str], conditional: bool, set_by: dict[str, dict]) -> None:
        default = argument.default_value
        if argument.name not in found:
            found[argument.name] = {
                "name": argument.name, "description": argument.description,
                "default": None if default is None else " + ".join(token.describe() for token in default),
                "value": None if default is None else evaluate(default), "file": file, "included_by": chain,
                "conditional": conditional or argument.condition is not None,
                "set_by": set_by.get(argument.name)}
        if argument.name not in context.launch_configurations and default is not None:
            value = evaluate(default)
            if value is not None:
                context.launch_configurations[argument.name] = value

    def include(entity, file: str, chain: list[str], conditional: bool) -> None:
        source = entity.launch_description_source
        try:
            description = source.get_launch_description(context)
        except Exception as error:  # noqa: BLE001 - a path known only at run time, a file that fails to load
            from roc.launch.files import one_line

            location = getattr(source, "_LaunchDescriptionSource__location", None)
            where = " + ".join(sub.describe() for sub in location) if location else source.location
            path = evaluate(location) if location else None
            where += f" ({path})" if path and path != where else ""
            unknown.append(f"{file}: cannot follow the include of {where}: {one_line(str(error))}")
            return
        set_by = {}
        for name, value in entity.launch_arguments:
            name, value = evaluate(name), evaluate(value)
            if name is not None:
                set_by[name] = {"file": file, "value": value}
                if value is not None:
                    context.launch_configurations[name] = value
        within(source.location, lambda: walk(description.entities, source.location, [*chain, file],
                                             conditional or entity.condition is not None, set_by))

    def within(file: str, visit) -> None:
        """``visit`` with the launch file's path known (ThisLaunchFileDir, $(dirname)), as when included."""
        context._push_locals()
        context.extend_locals({"current_launch_file_path": file,
                               "current_launch_file_directory": os.path.dirname(file)})
        try:
            visit()
        finally:
            context._pop_locals()

    def walk(entities, file: str, chain: list[str], conditional: bool, set_by: dict[str, dict]) -> bool:
        """False after a ResetLaunchConfigurations (no later argument is the command line's to set)."""
        for entity in entities:
            if isinstance(entity, DeclareLaunchArgument):
                declare(entity, file, chain, conditional, set_by)
            elif isinstance(entity, ResetLaunchConfigurations):
                return False
            elif isinstance(entity, IncludeLaunchDescription):
                include(entity, file, chain, conditional)
            else:
                if not walk(entity.describe_sub_entities(), file, chain, conditional, set_by):
                    return False
                for _, sub_entities in entity.describe_conditional_sub_entities():
                    walk(sub_entities, file, chain, True, set_by)
        return True

    top = get_launch_description_from_any_launch_file(path)
    within(os.path.abspath(path), lambda: walk(top.entities, os.path.abspath(path), [], False, {}))
    return {"file": os.path.abspath(path), "arguments": list(found.values()), "unknown": unknown}
