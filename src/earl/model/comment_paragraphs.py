"""A person's `//` comments around an element as plain paragraphs, for the SysML export's doc comments
and the document's tables."""

from __future__ import annotations

from earl.model.location import Comments


def comment_paragraphs(comments: Comments | None, closing: bool = True) -> list[str]:
    """A person's `//` comments as paragraphs of plain sentences: markers and separator rules dropped,
    the lines of one comment block joined (the doc is wrapped again as a whole). Of the comments above
    the element only the block next to it counts: one that a blank line parts from it heads a section
    of the file (an imported file's header above its first declaration), not the element. `closing`:
    with those that close the element's block (`// end of the arm's limits` before its `}`), written
    about it too, as is the one after its `}`; not the system's, which end the file (`// vim: set ft=earl:`)."""
    if comments is None:
        return []
    leading = list(comments.leading)
    if "" in leading:
        leading = leading[len(leading) - leading[::-1].index("") :]  # after the last blank line
    blocks = [
        leading,
        [comments.trailing] if comments.trailing else [],
        comments.closing if closing else [],
        [comments.after] if comments.after else [],
    ]
    result: list[str] = []
    for block in blocks:
        paragraph: list[str] = []
        for line in block:
            text = line.strip()
            text = text[2:] if text.startswith("//") else text
            text = text.strip()
            # A ruler (`// ---- Figure 9 …`) heads a section of the file, not the element under it.
            if not text or text.startswith("----"):
                if paragraph:
                    result.append(" ".join(paragraph))
                paragraph = []
                continue
            if paragraph and _starts_an_item(text):  # a list keeps its items apart
                result.append(" ".join(paragraph))
                paragraph = []
            paragraph.append(text)
        if paragraph:
            result.append(" ".join(paragraph))
    return result


def _starts_an_item(text: str) -> bool:
    """`- a point`, `* a point`, `1. a step`: a line that starts an item of a list."""
    head = text.split(maxsplit=1)[0]
    return head in ("-", "*", "•") or (head[:-1].isdigit() and head[-1] in ".)")
