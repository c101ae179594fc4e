"""Errors of the interaction layer and the status codes that carry them across it.

A reply carries a status code and, for errors, ``[type name, message, data]``; the caller's
node turns that back into the matching exception class with the same data, whether the
provider ran in the same process or in another one.
"""

from obsw.compat import const

OK = const(0)
PROVIDER_ERROR = const(1)  # the provider raised an exception of its own
COMPONENT_ERROR = const(2)  # the provider raised ComponentError on purpose
UNKNOWN_MEMBER = const(3)  # no such component or member, or the wrong kind of access
READ_ONLY = const(4)  # set on a data attribute
BAD_ARGUMENTS = const(5)  # wrong number of arguments for an operation
CYCLE = const(6)  # the call would close a cycle of synchronous calls
UNAVAILABLE = const(7)  # no provider reachable under that name
TIMEOUT = const(8)  # no reply within the caller's timeout
BUSY = const(9)  # the provider's inbox refused the request


class InteractionError(RuntimeError):
    """Base class: a call through the interaction layer did not give a value.

    ``target`` is ``"Component.member"``, ``data`` whatever the far side attached.
    """

    status = PROVIDER_ERROR

    def __init__(self, message, target=None, data=None):
        super().__init__(message)
        self.message = message
        self.target = target
        self.data = data


class ProviderError(InteractionError):
    """The provider raised; ``type`` names its exception class, ``data`` holds its args."""

    status = PROVIDER_ERROR

    def __init__(self, message, target=None, data=None, type=None):
        super().__init__(message, target, data)
        self.type = type


class ComponentError(InteractionError):
    """Raised by a provider on purpose; reaches the caller as this class with ``code`` and
    ``data`` intact."""

    status = COMPONENT_ERROR

    def __init__(self, code, message="", data=None, target=None):
        super().__init__(message or str(code), target, data)
        self.code = code


class UnknownMemberError(InteractionError):
    status = UNKNOWN_MEMBER


class ReadOnlyError(InteractionError):
    status = READ_ONLY


class ArgumentError(InteractionError):
    status = BAD_ARGUMENTS


class CycleError(InteractionError):
    """A synchronous call would close a cycle; ``cycle`` lists the components in order."""

    status = CYCLE

    def __init__(self, message, target=None, data=None):
        super().__init__(message, target, data)
        self.cycle = tuple(data) if data else ()


class UnavailableError(InteractionError):
    status = UNAVAILABLE


class CallTimeoutError(InteractionError):
    status = TIMEOUT


class BusyError(InteractionError):
    status = BUSY


_BY_STATUS = {
    PROVIDER_ERROR: ProviderError,
    COMPONENT_ERROR: ComponentError,
    UNKNOWN_MEMBER: UnknownMemberError,
    READ_ONLY: ReadOnlyError,
    BAD_ARGUMENTS: ArgumentError,
    CYCLE: CycleError,
    UNAVAILABLE: UnavailableError,
    TIMEOUT: CallTimeoutError,
    BUSY: BusyError,
}


def cycle_error(cycle, target=None):
    names = list(cycle)
    return CycleError(
        "synchronous call would close a cycle: %s (make one of these calls asynchronous)"
        % " -> ".join(names),
        target,
        names,
    )


def error_reply(exc):
    """``(status, [type, message, data])`` for an exception raised while serving a request."""
    if isinstance(exc, ComponentError):
        return COMPONENT_ERROR, ["ComponentError", exc.message, [exc.code, exc.data]]
    if isinstance(exc, InteractionError):
        return exc.status, [type(exc).__name__, exc.message, exc.data]
    args = list(exc.args)
    message = str(args[0]) if args else type(exc).__name__
    return PROVIDER_ERROR, [type(exc).__name__, message, args]


def error_from_reply(status, value, target):
    """The exception a caller raises for an error reply."""
    try:
        type_name, message, data = value
    except (TypeError, ValueError):
        type_name, message, data = "?", repr(value), None
    if status == COMPONENT_ERROR:
        try:
            code, data = data
        except (TypeError, ValueError):
            code = None
        return ComponentError(code, message, data, target)
    if status == PROVIDER_ERROR:
        return ProviderError(
            "%s raised %s: %s" % (target, type_name, message), target, data, type_name
        )
    cls = _BY_STATUS.get(status, InteractionError)
    return cls(message, target, data)
