"""The one undo command: a scene snapshot before and after an edit (scenes are immutable-style
values, so undo is just putting the previous snapshot back)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtGui import QUndoCommand

if TYPE_CHECKING:
    from ..scene import Scene
    from .document import SceneDocument, SelectionKey

MERGE_ID = 0x5CE7E


class SceneEdit(QUndoCommand):
    """Replace the document's scene by ``after``; undo puts ``before`` back. Consecutive edits
    with the same ``merge_key`` (a slider drag, a mouse orbit) merge into one undo step."""

    def __init__(
        self,
        doc: SceneDocument,
        before: Scene,
        after: Scene,
        text: str,
        *,
        select_before: SelectionKey | None,
        select_after: SelectionKey | None,
        merge_key: object = None,
    ) -> None:
        super().__init__(text)
        self.doc = doc
        self.before = before
        self.after = after
        self.select_before = select_before
        self.select_after = select_after
        self.merge_key = merge_key
        #: undone for good (a cancelled G/R/S move): the stack forgets it, nothing to redo
        self.forget_on_undo = False

    def redo(self) -> None:
        self.doc._replace(self.after, self.select_after)

    def undo(self) -> None:
        self.doc._replace(self.before, self.select_before)
        if self.forget_on_undo:
            self.setObsolete(True)

    def id(self) -> int:
        return MERGE_ID if self.merge_key is not None else -1

    def mergeWith(self, other: QUndoCommand) -> bool:  # noqa: N802 - Qt's name
        if not isinstance(other, SceneEdit) or other.merge_key != self.merge_key:
            return False
        self.after = other.after
        self.select_after = other.select_after
        if self.after == self.before:  # e.g. a colour picker cancelled: no step at all
            self.setObsolete(True)
        return True
