"""The FMI logger callbacks of this process, safe against fmpy's single logger proxy.

An FMU logs through a C-variadic function (`fmi2CallbackLogger(env, name, status,
category, format, ...)`) that ctypes cannot receive, so fmpy passes every logger
through a native proxy (`fmpy.logging.addLoggerProxy`) that formats the message and
calls **one process-global** Python target: the one registered last. `fmpy.simulate_fmu`
registers a logger it frees when it returns, after which every FMU instantiated with
fmpy's default callbacks (ours, or `fmpy.ssp.simulate_ssp`'s) calls freed memory the
next time it logs. That crashed the test process with a segfault inside `fmi2DoStep`.

Here the process keeps one logger that lives as long as the interpreter and routes
messages by instance name (a campaign keeps each instance's last messages; anything
else is printed the way fmpy prints). `callbacks()` re-points the proxy at it before
every instantiation, so whatever ran before (fmpy's `simulate_fmu` included) cannot
leave a dangling target behind for our instances.
"""

from __future__ import annotations

import ctypes
import threading
from collections.abc import Callable

from fmpy.fmi2 import (
    calloc,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
    free,
    printLogMessage,
)
from fmpy.logging import addLoggerProxy

#: Receives (status, category, message) for one instance name.
Route = Callable[[int, str, str], None]

_routes: dict[str, Route] = {}
_lock = threading.Lock()


def _log(env, instance, status, category, message) -> None:
    name = instance.decode(errors="replace") if instance else ""
    route = _routes.get(name)
    if route is None:
        printLogMessage(env, instance, status, category, message)
        return
    route(
        int(status),
        category.decode(errors="replace") if category else "",
        message.decode(errors="replace") if message else "",
    )


# Module globals: they live as long as the interpreter, so the proxy never outlives them.
_thunk = fmi2CallbackLoggerTYPE(_log)
_allocate = fmi2CallbackAllocateMemoryTYPE(calloc)
_free = fmi2CallbackFreeMemoryTYPE(free)
_callbacks = fmi2CallbackFunctions()
_callbacks.logger = _thunk
_callbacks.allocateMemory = _allocate
_callbacks.freeMemory = _free
# Replaces _callbacks.logger by the native proxy (which formats and calls _thunk).
addLoggerProxy(ctypes.byref(_callbacks))


def rearm() -> None:
    """Point fmpy's process-global proxy target back at this module's logger.

    A throw-away struct carries the target, so `_callbacks` (whose logger already is the
    proxy and which live instances may hold) is never modified."""
    carrier = fmi2CallbackFunctions()
    carrier.logger = _thunk
    with _lock:
        addLoggerProxy(ctypes.byref(carrier))


def callbacks() -> fmi2CallbackFunctions:
    """The callbacks to instantiate an FMU with (the proxy re-armed first)."""
    rearm()
    return _callbacks


def route(instance_name: str, receiver: Route) -> None:
    """Send the messages of `instance_name` to `receiver` instead of printing them."""
    _routes[instance_name] = receiver


def unroute(instance_name: str) -> None:
    _routes.pop(instance_name, None)
