"""The exception classes of spacar (issue 18): all derive from SpacarError, and none shadows a
builtin, not even through ``from spacar import *``."""
import builtins

import spacar
import spacar.errors


def test_every_error_derives_from_spacar_error():
    for name in spacar.errors.__all__:
        assert issubclass(getattr(spacar, name), spacar.SpacarError), name


def test_no_error_shadows_a_builtin():
    # spacar.NotImplementedError did (without deriving from the builtin); no element type lacks
    # its physics any more, so it is gone.
    assert not hasattr(spacar, "NotImplementedError")
    namespace: dict = {}
    exec("from spacar import *", namespace)
    assert not set(namespace) & set(dir(builtins)) - {"__builtins__"}
