"""mkdocs hook: the docstrings' Sphinx roles (``:class:`~a.b.C```, ``:func:`f```) shown as code, the way Sphinx shows
them (a leading ``~`` keeps the last name only), instead of the role's raw text."""

import re

_ROLE = re.compile(r":(?:class|func|meth|mod|data|attr|exc|obj):\s*<code>(~?)([^<]+)</code>")


def on_page_content(html, **kwargs):
    return _ROLE.sub(lambda m: f"<code>{m.group(2).rsplit('.', 1)[-1] if m.group(1) else m.group(2)}</code>", html)
