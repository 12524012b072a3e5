"""The server's copy of an open document, with lines where the editor has them.

pygls cuts a document with `str.splitlines`, which also ends a line at \\f, \\v, \\x1c-\\x1e,
U+0085, U+2028 and U+2029. Editors end lines at LF, CRLF and CR only (LSP specification,
"Text Documents"), so an edit sent for one line landed on another and the copy drifted
from the editor's. A Document cuts lines with mercmac.source.LINE_END.

Every position the server reads or sends goes through it, counting characters in the
units the client and server agreed on (`positionEncoding`: UTF-16 unless the client
offers UTF-8 or UTF-32), while the compiler's spans count characters (code points): an
emoji is one character and two UTF-16 units, and a position counted in characters put a
formatting edit's end inside the last line. Reading: `offset_at` (an index
into the text) and `spot` (a 1-based line and column); sending: `position` and `range_of`.
"""
from __future__ import annotations

from lsprotocol import types as t
from pygls.workspace import TextDocument, Workspace

from mercmac.source import LINE_END, Span, split_lines


class Document(TextDocument):
    """A pygls TextDocument whose lines end at LF, CRLF or CR, as the editor's do."""

    _cut: tuple[str, list[int], list[str]] | None = None  # (source, line starts, lines)

    def _lines_of_source(self) -> tuple[list[int], list[str]]:
        """Where each line starts, and each line without its end; once per version."""
        source = self.source
        if self._cut is None or self._cut[0] is not source:
            starts = [0, *(m.end() for m in LINE_END.finditer(source))]
            self._cut = (source, starts, split_lines(source))
        return self._cut[1], self._cut[2]

    @property
    def lines(self) -> tuple[str, ...]:
        """The lines with their ends, as pygls's own methods expect them."""
        source = self.source
        starts, _ = self._lines_of_source()
        ends = starts[1:] + ([len(source)] if starts[-1] < len(source) else [])
        return tuple(source[a:b] for a, b in zip(starts, ends))

    def offset_at(self, position: t.Position) -> int:
        """The index into `source` of an LSP position: a character past the end of its
        line means the end of that line, a line past the last one the end of the text."""
        starts, lines = self._lines_of_source()
        if position.line >= len(starts):
            return len(self.source)
        line = lines[position.line]
        return starts[position.line] + self._index(line, position.character)

    def spot(self, position: t.Position) -> tuple[int, int]:
        """The 1-based line and column (in characters, as spans count) of an LSP position."""
        _, lines = self._lines_of_source()
        if position.line >= len(lines):
            return len(lines), len(lines[-1]) + 1
        return position.line + 1, self._index(lines[position.line], position.character) + 1

    def position(self, line: int, column: int) -> t.Position:
        """The LSP position of a 1-based line and column: a column past the end of its line
        means the end of the line, a line past the last one the end of the text."""
        return t.Position(*self.units(line, column))

    def units(self, line: int, column: int) -> tuple[int, int]:
        """`position` as (line, character), without making a Position: semantic tokens
        send hundreds of thousands of them as plain integers."""
        _, lines = self._lines_of_source()
        if line > len(lines):
            end = self.end()
            return end.line, end.character
        if line < 1:
            return 0, 0
        text = lines[line - 1]
        head = text[:min(max(column - 1, 0), len(text))]
        return line - 1, (len(head) if head.isascii()
                          else self.position_codec.client_num_units(head))

    def range_of(self, span: Span) -> t.Range:
        """The LSP range of a compiler span (its end column exclusive; an end of 0 means
        the start's line, and one character)."""
        end_line = span.end_line or span.line
        end_column = span.end_column or span.column + 1
        return t.Range(self.position(span.line, span.column),
                       self.position(end_line, end_column))

    def end(self) -> t.Position:
        """The position just past the last character."""
        starts, lines = self._lines_of_source()
        return t.Position(len(lines) - 1, self.position_codec.client_num_units(lines[-1]))

    def _index(self, line: str, units: int) -> int:
        """How many characters of `line` the first `units` client units cover."""
        if line.isascii():  # one unit per character in UTF-8, UTF-16 and UTF-32 alike
            return min(units, len(line))
        count = self.position_codec.client_num_units
        used = 0
        for index, character in enumerate(line):
            if used >= units:
                return index
            used += count(character)
        return len(line)

    def _apply_incremental_change(self, change: t.TextDocumentContentChangePartial) -> None:
        """Replace the text between the change's two positions, as the editor did."""
        start, end = self.offset_at(change.range.start), self.offset_at(change.range.end)
        source = self.source
        self._source = source[:start] + change.text + source[max(start, end):]


class Documents(Workspace):
    """pygls's workspace, keeping each open document as a Document."""

    def _create_text_document(self, doc_uri: str, source: str | None = None,
                              version: int | None = None,
                              language_id: str | None = None) -> Document:
        return Document(doc_uri, source=source, version=version, language_id=language_id,
                        sync_kind=self._sync_kind, position_codec=self.position_codec)

    def unopened(self, uri: str, text: str) -> Document:
        """A Document of a file the editor has not opened (a rig's program, as read), to
        send positions in it in the session's units."""
        return self._create_text_document(uri, source=text)
