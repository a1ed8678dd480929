"""Credentials out of everything gift shows or stores: URLs with ``user:password@`` or secret query parameters.

A URL such as ``http://user:SECRET@host/v1?api_key=KEY&api-version=2024-06-01`` is shown, logged, stored in
cache identities and recordings, and keyed on as ``http://user:***@host/v1?api_key=***&api-version=2024-06-01``:
the password (or the whole user-info when it is a bare ``TOKEN@host``) and the value of every query parameter
whose name looks like a credential (:data:`SECRET_PARAMETERS`) become ``***``. Other parameters are kept.

Only what is shown changes: the backends still send the full URL to the server. Two credentials for the same
server share one redacted form, so they share LM cache entries, which is right: the answer of a model does not
depend on who pays for it.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from urllib.parse import parse_qsl, quote, unquote, urlsplit, urlunsplit

MASK = "***"

#: Query parameter names (case-insensitive, ``-`` and ``_`` ignored) whose values are credentials: these
#: names, any name ending in ``key`` (``api_key``, ``x-api-key``, ``subscription-key``), and any name that
#: contains one of the longer ones (``access_token``, ``client_secret``, ``X-Amz-Signature``).
SECRET_PARAMETERS = ("key", "sig", "pwd", "jwt", "code", "token", "secret", "password", "passwd", "auth",
                     "signature", "credential", "session", "bearer")
_CONTAINED = SECRET_PARAMETERS[5:]

_URL = re.compile(r"\b[a-zA-Z][a-zA-Z0-9+.-]*://[^\s'\"<>`]+")


def _is_secret_name(name: str) -> bool:
    n = name.lower().replace("-", "").replace("_", "")
    return n in SECRET_PARAMETERS or n.endswith("key") or any(s in n for s in _CONTAINED)


def redact_url(url: str) -> str:
    """``url`` with its user-info and secret query values replaced by ``***`` (unchanged if it holds none)."""
    if not isinstance(url, str) or "://" not in url:
        return url
    try:
        parts = urlsplit(url)
        host = parts.netloc.rpartition("@")
    except ValueError:  # not parseable as a URL: hide everything after the scheme rather than leak it
        return url.split("://", 1)[0] + "://" + MASK
    netloc = parts.netloc
    if host[1]:
        user, colon, _ = host[0].partition(":")
        netloc = f"{user}:{MASK}@{host[2]}" if colon else f"{MASK}@{host[2]}"
    query = parts.query
    if query:
        pairs = parse_qsl(query, keep_blank_values=True)
        if any(_is_secret_name(k) for k, _ in pairs):
            query = "&".join(f"{quote(k, safe='')}={MASK if _is_secret_name(k) else quote(v, safe='')}"
                             for k, v in pairs)
    if netloc == parts.netloc and query == parts.query:
        return url
    return urlunsplit(parts._replace(netloc=netloc, query=query))


def url_secrets(url: str) -> list[str]:
    """The credential strings inside ``url`` (password, user-info, secret query values), raw and decoded,
    longest first: what :func:`redact_text` must also remove from messages that quote them differently."""
    if not isinstance(url, str) or "://" not in url:
        return []
    try:
        parts = urlsplit(url)
    except ValueError:
        return []
    found: set[str] = set()
    userinfo, at, _ = parts.netloc.rpartition("@")
    if at and userinfo:
        found.add(userinfo)  # "user:password", or a bare token
        user, colon, password = userinfo.partition(":")
        if colon and password:  # the user name alone is no secret (and would blank out ordinary words)
            found.add(password)
    for k, v in parse_qsl(parts.query, keep_blank_values=True):
        if _is_secret_name(k) and v:
            found.add(v)
            found.add(quote(v, safe=""))
    found |= {unquote(s) for s in found}
    # very short strings (a user name "a") would blank out unrelated text; 4+ characters are replaced
    return sorted((s for s in found if len(s) >= 4), key=len, reverse=True)


def redact_text(text: str, secrets: Iterable[str] = ()) -> str:
    """``text`` with every URL in it redacted (:func:`redact_url`) and every string in ``secrets`` (for
    example :func:`url_secrets` of a URL, or an API key) replaced by ``***``."""
    if not isinstance(text, str) or not text:
        return text
    out = _URL.sub(lambda m: redact_url(m.group(0)), text)
    for s in sorted({s for s in secrets if s}, key=len, reverse=True):
        out = out.replace(s, MASK)
    return out


__all__ = ["MASK", "SECRET_PARAMETERS", "redact_text", "redact_url", "url_secrets"]
