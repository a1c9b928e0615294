"""A quick reader for the plain YAML spec files are written in, with the node interface
of PyYAML's composer; anything else is left to PyYAML.

Importing PyYAML costs a warm ``singcheck run`` more than its certification (its reader
compiles a Unicode-wide regular expression at import).  Spec files use a small part of
YAML: block mappings and sequences indented with spaces, ``- key: value`` items, flow
lists and mappings on one line (``[0, 4]``, ``{l: 2}``), plain scalars, comments and
``---`` between documents.  :func:`compose_all` reads exactly that and returns ``None``
for anything else — quotes, tags, anchors, aliases, block scalars, tabs, scalars over
several lines, directives, keys that are not plain names, a scalar PyYAML would resolve
to a timestamp or a merge key, nesting deeper than the caller's bound — and then the
caller composes the text with PyYAML (which also names the error of a broken file).
So every text it accepts composes to the nodes PyYAML gives it: the same kinds, the same
scalar texts and the same lines (``tests/test_spec.py`` compares the two).

Nodes have PyYAML's ``id`` (``scalar``, ``sequence``, ``mapping``), ``tag``, ``value``
(a string, a list of nodes, or a list of (key, value) pairs) and ``start_mark.line``
(0-based).  Scalars are tagged as strings: spec scalars are read as text anyway, and
what PyYAML would tag otherwise (timestamps, ``<<``, ``=``) is declined.
"""

from __future__ import annotations

import re

_STR, _SEQ, _MAP = (f"tag:yaml.org,2002:{t}" for t in ("str", "seq", "map"))


class Mark:
    __slots__ = ("line", "column")

    def __init__(self, line: int, column: int) -> None:
        self.line, self.column = line, column


class Node:
    __slots__ = ("tag", "value", "start_mark")
    id = "node"

    def __init__(self, tag: str, value, line: int, column: int) -> None:
        self.tag, self.value, self.start_mark = tag, value, Mark(line, column)


class ScalarNode(Node):
    __slots__ = ()
    id = "scalar"


class SequenceNode(Node):
    __slots__ = ()
    id = "sequence"


class MappingNode(Node):
    __slots__ = ()
    id = "mapping"


def kind(node) -> str | None:
    """``scalar``, ``sequence`` or ``mapping`` for a node of this module or PyYAML's."""
    return getattr(node, "id", None)


class _Decline(Exception):
    """Not in the plain subset: PyYAML composes the text instead."""


#: characters no accepted line may hold (quotes, tags, anchors, block scalars, …)
_REFUSED = set("'\"!&|>%@`\t\r\\")
_KEY = re.compile(r"([A-Za-z_][A-Za-z0-9_]*):(?: +(.*))?\Z")
_ITEM = re.compile(r"- +(.*)\Z")
#: scalar texts PyYAML's resolver tags as neither str, int, float, bool nor null
_SPECIAL = re.compile(r"[0-9][0-9][0-9][0-9]-|<<\Z|=\Z")
_FLOW_STOP = re.compile(r"[,\[\]{}:?]")


def compose_all(text: str, max_depth: int, offset: int = 0) -> list[Node] | None:
    """The documents of ``text``, or ``None`` when the text is not in the plain subset
    (or has an empty document, or nests lists and mappings deeper than ``max_depth``);
    ``offset``: lines of the file before ``text`` (added to every node's line)."""
    try:
        docs = [_Document(lines, max_depth).node() for lines in _documents(text, offset)]
    except _Decline:
        return None
    return docs if None not in docs else None  # an empty document: as PyYAML sees it


def _documents(text: str, offset: int = 0) -> list[list[tuple[int, int, str]]]:
    """Per document, its non-blank lines as (line number, indent, content without the
    comment)."""
    docs: list[list[tuple[int, int, str]]] = [[]]
    for number, raw in enumerate(text.split("\n"), offset):
        if not raw.isprintable():  # (stricter than YAML's printable set)
            raise _Decline
        content = _without_comment(raw).rstrip(" ")
        if not content:
            continue
        if content == "---":
            docs.append([])
            continue
        if content.startswith(("---", "...", "%")) or _REFUSED.intersection(content):
            raise _Decline
        stripped = content.lstrip(" ")
        docs[-1].append((number, len(content) - len(stripped), stripped))
    if not docs[0] and len(docs) > 1:
        docs.pop(0)  # a leading --- opens the first document
    return docs


def _without_comment(line: str) -> str:
    """The line up to a comment: ``#`` at its start or after a space."""
    at = line.find("#")
    while at > 0 and line[at - 1] != " ":
        at = line.find("#", at + 1)
    return line if at < 0 else line[:at]


class _Document:
    def __init__(self, lines: list[tuple[int, int, str]], max_depth: int) -> None:
        self.lines, self.i, self.max_depth = lines, 0, max_depth

    def node(self) -> Node | None:
        if not self.lines:
            return None
        number, indent, _ = self.lines[0]
        out = self.block(indent, 1)
        if self.i != len(self.lines):
            raise _Decline  # a line left over at a smaller indent
        return out

    def block(self, indent: int, depth: int) -> Node:
        """The mapping or sequence whose entries start at column ``indent``."""
        if depth > self.max_depth:
            raise _Decline
        number, column, content = self.lines[self.i]
        if column != indent:
            raise _Decline
        if content == "-" or content.startswith("- "):
            return self.sequence(indent, depth)
        return self.mapping(indent, depth, content)

    def sequence(self, indent: int, depth: int) -> Node:
        number, _, _ = self.lines[self.i]
        items: list[Node] = []
        while self.i < len(self.lines):
            line, column, content = self.lines[self.i]
            if column < indent:
                break
            m = _ITEM.match(content)
            if column != indent or m is None:
                raise _Decline  # '-' alone, or a stray line
            rest = m.group(1)
            at = column + len(content) - len(rest)
            if _KEY.match(rest):  # "- key: value": a mapping starting on the item's line
                self.lines[self.i] = (line, at, rest)
                items.append(self.mapping(at, depth + 1, rest))
            else:
                self.i += 1
                items.append(self.inline(rest, line, at, depth + 1))
                self.no_continuation(indent)
        return SequenceNode(_SEQ, items, number, indent)

    def mapping(self, indent: int, depth: int, first: str) -> Node:
        number = self.lines[self.i][0]
        pairs: list[tuple[Node, Node]] = []
        while self.i < len(self.lines):
            line, column, content = self.lines[self.i]
            if column < indent:
                break
            m = _KEY.match(content)
            if column != indent or m is None:
                raise _Decline
            key = ScalarNode(_STR, m.group(1), line, column)
            if _SPECIAL.match(m.group(1)):
                raise _Decline
            rest = m.group(2)
            self.i += 1
            if rest:
                value = self.inline(rest, line, column + len(content) - len(rest), depth + 1)
                self.no_continuation(indent)
            else:  # the value is the block indented below (nothing there: decline)
                if self.i == len(self.lines) or self.lines[self.i][1] <= indent:
                    raise _Decline
                value = self.block(self.lines[self.i][1], depth + 1)
            pairs.append((key, value))
        return MappingNode(_MAP, pairs, number, indent)

    def no_continuation(self, indent: int) -> None:
        """A line more indented after an inline value would continue it: decline."""
        if self.i < len(self.lines) and self.lines[self.i][1] > indent:
            raise _Decline

    def inline(self, text: str, line: int, column: int, depth: int) -> Node:
        """A value written on one line: a flow collection or a plain scalar."""
        if text[0] in "[{":
            node, end = _Flow(text, line, column, self.max_depth).collection(0, depth)
            if text[end:].strip():
                raise _Decline
            return node
        return _scalar(text, line, column, block=True)


def _scalar(text: str, line: int, column: int, block: bool) -> ScalarNode:
    """A plain scalar (trimmed ``text`` at ``column``), or decline."""
    value = text.strip(" ")
    if not value or value[0] in "?:,[]{}#&*!|>'\"%@`" or \
            value[0] == "-" and (len(value) == 1 or value[1] == " ") or \
            ":" in value or _SPECIAL.match(value) or block and " #" in value:
        raise _Decline
    return ScalarNode(_STR, value, line, column + len(text) - len(text.lstrip(" ")))


class _Flow:
    """``[…]`` and ``{…}`` on one line, with plain scalars inside."""

    def __init__(self, text: str, line: int, column: int, max_depth: int) -> None:
        self.text, self.line, self.column, self.max_depth = text, line, column, max_depth

    def collection(self, pos: int, depth: int) -> tuple[Node, int]:
        if depth > self.max_depth:
            raise _Decline
        opening = self.text[pos]
        closing = "]" if opening == "[" else "}"
        start = self.column + pos
        values: list = []
        pos = self.skip(pos + 1)
        if self.at(pos) == closing:
            return (SequenceNode(_SEQ, values, self.line, start) if opening == "[" else
                    MappingNode(_MAP, values, self.line, start)), pos + 1
        while True:
            if opening == "[":
                item, pos = self.value(pos, depth)
                values.append(item)
            else:
                key, pos = self.plain(pos)
                if _SPECIAL.match(key.value) or self.at(pos) != ":" or \
                        self.at(pos + 1) != " ":
                    raise _Decline
                item, pos = self.value(self.skip(pos + 1), depth)
                values.append((key, item))
            pos = self.skip(pos)
            if self.at(pos) == closing:
                break
            if self.at(pos) != ",":
                raise _Decline
            pos = self.skip(pos + 1)
            if self.at(pos) in (closing, ","):
                raise _Decline  # a trailing or doubled comma
        node = SequenceNode(_SEQ, values, self.line, start) if opening == "[" else \
            MappingNode(_MAP, values, self.line, start)
        return node, pos + 1

    def value(self, pos: int, depth: int) -> tuple[Node, int]:
        if self.at(pos) in ("[", "{"):
            return self.collection(pos, depth + 1)
        return self.plain(pos)

    def plain(self, pos: int) -> tuple[ScalarNode, int]:
        m = _FLOW_STOP.search(self.text, pos)
        end = m.start() if m else len(self.text)
        return _scalar(self.text[pos:end], self.line, self.column + pos, block=False), end

    def skip(self, pos: int) -> int:
        while self.at(pos) == " ":
            pos += 1
        return pos

    def at(self, pos: int) -> str:
        return self.text[pos] if pos < len(self.text) else ""
