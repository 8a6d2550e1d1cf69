"""Text from outside (a recording, a vehicle) made safe to print: every control and format
character — ESC of a terminal escape sequence (OSC 0 sets the window title, OSC 52 writes the
clipboard), NUL, BEL, a line break that would forge a line of output, a bidirectional
override such as U+202E that reorders what follows — shown as an escape instead."""

from __future__ import annotations

import unicodedata

_UNSAFE = ("Cc", "Cf", "Cs", "Co", "Cn", "Zl", "Zp")


def safe_text(text: str) -> str:
    """``text`` with each unsafe character written as ``\\xNN``, ``\\uNNNN`` or ``\\UNNNNNNNN``
    (as Python's ``repr`` writes it); printable text is left as it is."""
    if text.isprintable():
        return text
    return "".join(_escape(c) if unicodedata.category(c) in _UNSAFE else c for c in text)


def _escape(c: str) -> str:
    code = ord(c)
    if code < 0x100:
        return f"\\x{code:02x}"
    return f"\\u{code:04x}" if code < 0x10000 else f"\\U{code:08x}"


def counted(n: int, noun: str, plural: str | None = None) -> str:
    """``1 flight``, ``0 flights``, ``3 flights`` (``plural`` when it is not noun + s)."""
    return f"{n} {noun if n == 1 else plural or noun + 's'}"
