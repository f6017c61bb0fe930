"""One call into the Fortran engine at a time in a process.

The engine's calls release the interpreter (f2py ``threadsafe``), so other Python threads run
while a scene runs. Two engine calls at once, however, are not safe with the compiler this
project builds with: gfortran 12 keeps the length of a deferred-length character function
result (``character(len=:), allocatable``) in a static variable at each call site, so two
threads building text at the same place (a scene's canonical text, a run's attributes) clobber
each other's lengths — measured: four threads reading one scene's canonical text got garbled
text in 290 of 1,200 calls. Every engine call of the Python layer goes through
:func:`engine_call`, which holds one lock for its duration: threads stay correct, and engine
calls from several threads run one after the other. Several cores take separate processes
(``python -m beamstops sweep -j``, MPI).
"""

from __future__ import annotations

import threading
from typing import Any, Callable

_ENGINE = threading.Lock()


def engine_call(function: Callable[..., Any], *args: Any) -> Any:
    """``function(*args)`` (an f2py entry point of ``beamstops._engine``) with the engine's lock held."""
    with _ENGINE:
        return function(*args)
