"""A stand-in for a Blender UI layout that records what a panel's real ``draw`` puts in it: label
texts, "prop:NAME" for each property drawn and "op:IDNAME" for each operator button (the panel
tests read the panel as a user would see it; not a test module)."""
from __future__ import annotations

from types import SimpleNamespace


class Layout:
    """Records labels, properties and operators; accepts the other calls a panel makes."""

    def __init__(self, log: list):
        self.log = log

    def label(self, text="", icon="NONE", **_):
        self.log.append(text)

    def _child(self, *_, **__):
        return Layout(self.log)

    box = column = row = grid_flow = split = _child

    def prop(self, data, name, *_, **__):
        self.log.append(f"prop:{name}")

    def operator(self, idname, *_, **__):
        self.log.append(f"op:{idname}")
        return SimpleNamespace()

    def progress(self, *_, **__):
        pass


def drawn(panel_cls, context) -> list:
    """What ``panel_cls.draw`` shows in ``context``, in order (see ``Layout``)."""
    log: list = []
    panel_cls.draw(SimpleNamespace(layout=Layout(log)), context)
    return log
