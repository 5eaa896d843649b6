"""MkDocs hook (mkdocs.yml): links from docs/ to the rest of the repository.

On GitHub a page links the notebooks as ``[...](../notebooks/x.ipynb)``; the site holds only
docs/, where MkDocs would warn about such a link and strict mode would fail. This hook checks that
every such target exists in the repository (the build fails otherwise, as for a broken link inside
docs/) and writes it in the site as its path in the repository instead of a link.
"""
from __future__ import annotations

import re
from pathlib import Path

from mkdocs.exceptions import PluginError

# [text](../target) with the target outside docs/ (an anchor or title is not used on such links).
_OUTSIDE = re.compile(r"\[([^\]]+)\]\((\.\./[^)\s#]+)\)")


def on_page_markdown(markdown, page, config, files):
    docs = Path(config["docs_dir"]).resolve()
    page_dir = (docs / page.file.src_path).parent
    root = docs.parent

    def plain(m):
        text, target = m.group(1), m.group(2)
        path = (page_dir / target).resolve()
        if not path.exists():
            raise PluginError(f"{page.file.src_path}: broken link {target}")
        rel = path.relative_to(root).as_posix()
        return text if rel in text else f"{text} (`{rel}` in the repository)"

    return _OUTSIDE.sub(plain, markdown)
