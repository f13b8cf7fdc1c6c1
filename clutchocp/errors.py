"""Exception hierarchy of clutchocp.

Every user mistake raises a subclass of :class:`ClutchocpError` whose message is one
line naming the field and what is allowed; the command line turns it into exit code 2.
The classes also subclass the matching built-in so callers can catch ``ValueError`` etc.
"""


class ClutchocpError(Exception):
    """Base class of every error clutchocp raises on purpose.

    The message is kept on one line: line breaks (e.g. inside a user's key) are shown escaped.
    """

    def __init__(self, message=""):
        text = str(message)
        super().__init__(text.replace("\r", "\\r").replace("\n", "\\n"))


class SceneError(ClutchocpError, ValueError):
    """A scene file (or an override of it) is not valid."""


class UnknownKeyError(SceneError):
    """A key that the scene format does not know (the message suggests the closest one)."""


class MissingParameterError(SceneError):
    """A required parameter is absent."""


class ParameterTypeError(SceneError, TypeError):
    """A parameter has the wrong type (e.g. text where a number is expected)."""


class PhysicalRangeError(SceneError):
    """A value outside its physical range (negative radius, zero viscosity, r1 >= r2 ...)."""


class UnknownVariantError(SceneError):
    """A part variant (``model = ...``) that does not exist."""


class UnitError(SceneError):
    """A unit that does not parse or has the wrong dimension."""


class SceneNotFoundError(SceneError, FileNotFoundError):
    """Neither a built-in scene name nor an existing file."""


class ModelError(ClutchocpError, ValueError):
    """A request the model cannot honour (e.g. an analysis the scene does not support)."""


class SolverError(ClutchocpError, RuntimeError):
    """A numerical solver failed; the message says when, where and why."""


class OptionError(ClutchocpError, ValueError):
    """A command-line option or API argument has a value that is not allowed."""


class OutputFolderError(ClutchocpError, ValueError):
    """An output folder that cannot be written (a file, an unwritable parent, in use by another run)."""


class ResourceLimitError(SceneError):
    """A size (output points, plate interfaces ...) beyond what a run can hold in memory and time."""


class ModelEdgeError(SolverError):
    """A run reached the edge of what its model describes (a film gap closed to zero: the contact could not
    carry the load); the run ends there and reports no result. The message names the part, the time and
    the cause."""


class PlausibilityWarning(UserWarning):
    """A scene value outside what wet clutches have (``clutchocp.scene.schema.Span``): the run goes on."""
