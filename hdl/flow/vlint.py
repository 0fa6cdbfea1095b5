"""A signedness check of MyHDL's Verilog: operands of mixed signedness in one expression.

MyHDL's VHDL back end gives every operator operands of one type (it resizes and converts an unsigned
operand next to a signed one), so the VHDL computes what the Python computes. Its Verilog back end
writes the expression as it is, and Verilog's rule differs: when one operand of an operator is unsigned,
the whole expression is evaluated unsigned, and a signed operand is *zero*-extended to the expression's
width. ``det4 - (ktt << 2)`` with ``det4`` signed and ``ktt`` unsigned turns a negative ``det4`` into a
large positive number. This module finds such expressions in a generated Verilog file, so ``make
verilog`` and the tests can refuse them before a simulation shows the damage.

The parser knows the subset of Verilog that MyHDL writes (one statement per line; ``assign``, ``<=``,
``=``, ``if``/``case`` conditions; ``$signed``/``$unsigned``, selects, concatenations, ``?:``). Rules
(IEEE 1364-2005 5.5): an unsized decimal constant is signed; a sized one (``8'd3``), a bit or part
select and a concatenation are unsigned; a memory word has its memory's signedness; the right operand
of a shift and the operands of ``&& || !``, selects and concatenations are self-determined. Mixing a
non-negative constant with unsigned operands is harmless and not reported.
"""

from __future__ import annotations

import re

_DECL = re.compile(r"^\s*(?:input|output|inout|reg|wire|integer)\b(?:\s+(?:reg|wire))?(\s+signed)?\s*(\[[^\]]*\])?"
                   r"\s*(\w+)\s*(\[[^\]]*\])?", re.M)
_TOKEN = re.compile(r"\s*(\d+'s?[bdhoBDHO][0-9a-fA-FxzXZ_]+|\d+|\$signed|\$unsigned|\w+|<<<|>>>|===|!==|<<|>>|<=|>="
                    r"|==|!=|&&|\|\||~\^|\^~|\*\*|[-+*/%<>!~&|^?:()\[\]{},])")

_BINARY = [("||",), ("&&",), ("|",), ("^", "~^", "^~"), ("&",), ("==", "!=", "===", "!=="),
           ("<", "<=", ">", ">="), ("<<", ">>", "<<<", ">>>"), ("+", "-"), ("*", "/", "%"), ("**",)]
_LOGICAL = {"||", "&&"}
_SHIFT = {"<<", ">>", "<<<", ">>>"}


class _Node:
    """An expression node: ``signed`` per Verilog's rules; ``const`` the value of a constant, else None."""

    def __init__(self, signed: bool, const: int | None = None, text: str = ""):
        self.signed, self.const, self.text = signed, const, text


class _Parser:
    def __init__(self, tokens: list[str], decls: dict[str, tuple[bool, bool]], problems: list[str]):
        self.t, self.i, self.decls, self.problems = tokens, 0, decls, problems

    def peek(self):
        return self.t[self.i] if self.i < len(self.t) else None

    def take(self, expect=None):
        tok = self.peek()
        if expect is not None and tok != expect:
            raise SyntaxError(f"expected {expect!r}, found {tok!r}")
        self.i += 1
        return tok

    def expr(self) -> _Node:
        cond = self.binary(0)
        if self.peek() == "?":
            self.take()
            a = self.expr()
            self.take(":")
            b = self.expr()
            return self.combine(a, b, "?:")
        return cond

    def binary(self, level: int) -> _Node:
        if level == len(_BINARY):
            return self.unary()
        left = self.binary(level + 1)
        while self.peek() in _BINARY[level]:
            op = self.take()
            right = self.binary(level + 1)
            if op in _LOGICAL:
                left = _Node(False, text=f"{left.text} {op} {right.text}")
            elif op in _SHIFT:
                left = _Node(left.signed, text=f"{left.text} {op} {right.text}")
            elif op in ("==", "!=", "===", "!==", "<", "<=", ">", ">="):
                self.combine(left, right, op)
                left = _Node(False, text=f"{left.text} {op} {right.text}")
            else:
                left = self.combine(left, right, op)
        return left

    def combine(self, a: _Node, b: _Node, op: str) -> _Node:
        if a.signed != b.signed:
            s, u = (a, b) if a.signed else (b, a)
            harmless = s.const is not None and s.const >= 0
            if not harmless:
                self.problems.append(f"{a.text} {op} {b.text}: {s.text} is signed, {u.text} unsigned")
            return _Node(False, text=f"{a.text} {op} {b.text}")
        const = None
        if a.const is not None and b.const is not None and op in ("+", "-", "*"):
            const = {"+": a.const + b.const, "-": a.const - b.const, "*": a.const * b.const}[op]
        return _Node(a.signed, const, f"{a.text} {op} {b.text}")

    def unary(self) -> _Node:
        tok = self.peek()
        if tok in ("-", "+", "~"):
            self.take()
            n = self.unary()
            const = -n.const if (tok == "-" and n.const is not None) else (n.const if tok == "+" else None)
            return _Node(n.signed, const, f"{tok}{n.text}")
        if tok in ("!", "&", "|", "^", "~^", "^~"):
            self.take()
            n = self.unary()
            return _Node(False, text=f"{tok}{n.text}")
        return self.primary()

    def primary(self) -> _Node:
        tok = self.take()
        if tok is None:
            raise SyntaxError("unexpected end of expression")
        if tok == "(":
            n = self.expr()
            self.take(")")
            return _Node(n.signed, n.const, f"({n.text})")
        if tok in ("$signed", "$unsigned"):
            self.take("(")
            n = self.expr()
            self.take(")")
            return _Node(tok == "$signed", n.const if tok == "$signed" else None, f"{tok}({n.text})")
        if tok == "{":
            parts = [self.expr()]
            while self.peek() == ",":
                self.take()
                parts.append(self.expr())
            if self.peek() == "{":  # replication {n{x}}
                self.take()
                self.expr()
                self.take("}")
            self.take("}")
            return _Node(False, text="{...}")
        if re.fullmatch(r"\d+", tok):
            return _Node(True, int(tok), tok)
        if "'" in tok:
            signed = "'s" in tok.lower()
            spec = tok.split("'")[1].lstrip("sS")
            base, digits = spec[0].lower(), spec[1:].replace("_", "")
            try:
                value = int(digits, {"b": 2, "d": 10, "h": 16, "o": 8}[base])
            except ValueError:
                value = None
            return _Node(signed, value, tok)
        if re.fullmatch(r"\w+", tok):
            signed, memory = self.decls.get(tok, (False, False))
            node = _Node(signed, text=tok)
            first = True
            while self.peek() == "[":
                self.take()
                self.expr()
                if self.peek() in (":", "+:", "-:"):
                    self.take()
                    self.expr()
                self.take("]")
                # A memory's first select is a word (its signedness); any other select is unsigned.
                node = _Node(signed if (memory and first) else False, text=f"{tok}[...]")
                first = False
            return node
        raise SyntaxError(f"unexpected {tok!r}")


def _tokens(text: str) -> list[str]:
    out, pos = [], 0
    text = text.rstrip()
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if not m:
            raise SyntaxError(f"cannot read {text[pos:pos + 20]!r}")
        out.append(m.group(1))
        pos = m.end()
    return out


def declarations(text: str) -> dict[str, tuple[bool, bool]]:
    """name -> (signed, is a memory) of every port, reg, wire and integer."""
    out = {}
    for signed, _, name, mem in _DECL.findall(text):
        out[name] = (bool(signed.strip()) or text.find(f"integer {name}") >= 0, bool(mem))
    return out


def _strip_comments(text: str) -> str:
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    return re.sub(r"//[^\n]*", "", text)


def _balanced(s: str, start: int) -> str:
    """The text inside the parenthesis that opens at ``s[start]``."""
    depth = 0
    for j in range(start, len(s)):
        depth += {"(": 1, ")": -1}.get(s[j], 0)
        if depth == 0:
            return s[start + 1:j]
    raise SyntaxError(f"unbalanced parenthesis in {s[start:start + 40]!r}")


def mixed_signedness(text: str) -> list[str]:
    """Every expression of a MyHDL Verilog file whose operands mix signed and unsigned, as one line each."""
    text = _strip_comments(text)
    decls = declarations(text)
    problems: list[str] = []
    body_lines = [l for l in text.splitlines()
                  if not re.match(r"\s*(input|output|inout|reg|wire|integer|module|endmodule|initial)\b", l)]
    for ln in body_lines:
        exprs = []
        m = re.match(r"\s*(?:assign\s+)?[\w\[\]\s:+\-]+?(?:<=|=)(?!=)\s*(.+);\s*$", ln)
        if m and not re.match(r"\s*(if|else|case|for|while)\b", ln):
            exprs.append(m.group(1))
        for c in re.finditer(r"\b(if|case|casez|while)\s*\(", ln):
            exprs.append(_balanced(ln, c.end() - 1))
        for e in exprs:
            found: list[str] = []
            try:
                p = _Parser(_tokens(e), decls, found)
                p.expr()
            except SyntaxError:
                continue  # not an expression this check reads (e.g. a for header): VHDL and benches cover it
            problems += [f"{f}   in: {ln.strip()}" for f in found]
    return problems
