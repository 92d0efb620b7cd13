"""`earl doc`: the spec as a document that reads like the manual's §3, in HTML and in Markdown.

`build.py` turns a system into a neutral tree (`tree.py`) of sections, tables and
figures; `html.py` and `markdown.py` print that tree; `site.py` draws the
diagrams and writes the files.  Both outputs therefore say the same thing.
"""

from earl.render.document.site import DocumentResult, NotOurs, write_doc, write_site

__all__ = ["DocumentResult", "NotOurs", "write_doc", "write_site"]
