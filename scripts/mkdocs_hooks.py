"""MkDocs hooks of the documentation site (mkdocs.yml, ``hooks:``).

The package's docstrings cross-reference with Sphinx roles (``:class:`~mimo_social.x.Y```);
the API pages render them as code, so the role's name (``:class:``) and the ``~`` that asks
for the short name would show as text. ``on_page_content`` drops both: ``:class:`~a.b.Y```
reads ``Y``, ``:func:`a.b.f``` reads ``a.b.f``.
"""

from __future__ import annotations

import re

ROLE = re.compile(r":(?:py:)?(?:class|meth|func|mod|data|attr|obj|exc|const):(?=<code>)")
TILDE = re.compile(r"<code>~(?:\w+\.)*(\w+)</code>")


def on_page_content(html: str, **kwargs) -> str:
    return TILDE.sub(r"<code>\1</code>", ROLE.sub("", html))
