"""The one exception type for problems with the user's input or files.

Raise ``ShapeMoveError`` with a message that names the problem and, where it helps, what to do.
The command line prints it as a single line; the Blender UI shows it in a report.
"""


class ShapeMoveError(ValueError):
    pass
