"""Library bindings made into skill types: a skill by configuration, no code.

:func:`bound_skill_type` resolves a :class:`~rosmc_server.core.skills.bindings.BindingSpec` when
the executor starts: the message types by name, every field against its parameter, the
status and outcome texts against the feedback and result. Anything that does not fit
stops the executor with a :class:`SkillSetupError` of one sentence. It also makes the
action client, service proxy or publisher then, so their connections are up by the time
the skill runs.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

import actionlib
import genpy
import rospy
from roslib.message import get_service_class

from rosmc_server.core import SkillSetupError, SkillSpec
from rosmc_server.core.skills.bindings import BindingKind, BindingSpec

from ..core import SkillBehavior, SkillType
from ..core.fitting import parameter_types
from .bound_skills import ActionSkill, Reply, ServiceSkill, TopicSkill
from .message_fields import MessageRecipe, Template, bool_field, message_class

QUEUE_SIZE = 10


def bound_skill_type(spec: SkillSpec) -> SkillType:
    """The skill type of a library skill with a binding; SkillSetupError if it does not fit."""
    binding = spec.binding
    assert binding is not None
    where = f"skill '{spec.name}' bound to {binding.describe()}"
    makers = {
        BindingKind.ACTION: _action,
        BindingKind.SERVICE: _service,
        BindingKind.TOPIC: _topic,
    }
    create = makers[binding.kind](spec, binding, where)
    return SkillType(spec.name, create, parameter_types(spec), spec.description)


def _action(spec: SkillSpec, binding: BindingSpec, where: str) -> Callable[[], SkillBehavior]:
    base = binding.type.removesuffix("Action")
    action, goal, result, feedback = (
        message_class(f"{base}{part}", where) for part in ("Action", "Goal", "Result", "Feedback")
    )
    recipe = MessageRecipe.make(goal, binding.fields, parameter_types(spec), where)
    status = Template.make(binding.status, feedback, where)
    reply = _reply(binding, result, where)
    client = actionlib.SimpleActionClient(binding.name, action)
    return functools.partial(ActionSkill, client, binding.name, recipe, status, reply)


def _reply(binding: BindingSpec, message: type[genpy.Message], where: str) -> Reply:
    """How the result or response ``message`` becomes the outcome."""
    text = Template.make(binding.outcome, message, where)
    return Reply(text, bool_field(message, binding.success, where))


def _service(spec: SkillSpec, binding: BindingSpec, where: str) -> Callable[[], SkillBehavior]:
    try:
        service = get_service_class(binding.type)
    except (ValueError, ImportError):
        service = None
    if service is None:
        raise SkillSetupError(f"{where}: there is no service type {binding.type} on this robot")
    request, response = service._request_class, service._response_class
    recipe = MessageRecipe.make(request, binding.fields, parameter_types(spec), where)
    reply = _reply(binding, response, where)
    proxy = rospy.ServiceProxy(binding.name, service)
    return functools.partial(ServiceSkill, proxy, binding.name, recipe, reply)


def _topic(spec: SkillSpec, binding: BindingSpec, where: str) -> Callable[[], SkillBehavior]:
    message = message_class(binding.type, where)
    recipe = MessageRecipe.make(message, binding.fields, parameter_types(spec), where)
    publisher = rospy.Publisher(binding.name, message, queue_size=QUEUE_SIZE)
    return functools.partial(TopicSkill, publisher, recipe)
