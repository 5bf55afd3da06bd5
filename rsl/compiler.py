"""Check an RSL program against a robot profile and compile it to a typed plan.

The parser is driven by the profile: it knows statements only as
`word arg, arg;` and looks each word up among the profile's skills, so a new
skill needs no code. It recovers after every bad statement and reports all
errors of a program in one pass.
"""

from __future__ import annotations

import difflib
import math
import unicodedata
from collections.abc import Collection
from dataclasses import dataclass

from rsl.diagnostics import Code, Diagnostic
from rsl.lexer import Kind, SourceMap, Token, tokenize
from rsl.plan import Arg, Command, ObjectRef, Plan, Quantity
from rsl.profile import Param, Profile, Skill
from rsl.syntax import is_identifier


@dataclass(frozen=True)
class CompileResult:
    plan: Plan | None
    diagnostics: tuple[Diagnostic, ...]

    @property
    def ok(self) -> bool:
        return self.plan is not None and not self.diagnostics


def compile_program(
    source: str, profile: Profile, known_objects: Collection[str] | None = None
) -> CompileResult:
    """Parse and check `source`; the plan is present only when there is no error."""
    return _Compiler(source, profile, known_objects).run()


_ARGUMENT_KINDS = (Kind.NUMBER, Kind.IDENT, Kind.BAD_NUMBER, Kind.BAD_IDENT)


@dataclass
class _Statement:
    head: Token
    skill: Skill | None
    args: list[Token]
    last: Token
    # After one error in a statement the rest of it is not checked, so a
    # single mistake does not cascade into a screen of follow-on errors.
    broken: bool = False
    expect_comma: bool = False


class _Compiler:
    def __init__(self, source: str, profile: Profile, known_objects: Collection[str] | None) -> None:
        self.source = source
        self.profile = profile
        self.known = None if known_objects is None else frozenset(known_objects)
        self.lines = SourceMap(source)
        self.diagnostics: list[Diagnostic] = []
        self.commands: list[Command] = []
        self.statement: _Statement | None = None

    def run(self) -> CompileResult:
        for token in tokenize(self.source, self.lines):
            self.feed(token)
        if self.statement is not None:
            self.missing_semicolon(self.statement.last)
            self.statement = None
        if len(self.commands) > self.profile.max_statements:
            extra = self.commands[self.profile.max_statements]
            self.report(Code.TOO_LONG, extra.line, extra.column, extra.skill,
                        f"the program has {len(self.commands)} statements but this robot runs at most "
                        f"{self.profile.max_statements}; split the task into smaller programs")
        self.diagnostics.sort(key=lambda d: (d.line, d.column))
        plan = None if self.diagnostics else Plan(tuple(self.commands), self.profile.name)
        return CompileResult(plan, tuple(self.diagnostics))

    # -- the statement state machine -------------------------------------------------

    def feed(self, token: Token) -> None:
        kind = token.kind
        if kind is Kind.COMMENT:
            return
        if kind is Kind.ILLEGAL:
            self.report(Code.ILLEGAL_CHARACTER, token.line, token.column, token.text,
                        f"`{token.text}` cannot appear in RSL; remove it. A statement is a command, "
                        "its arguments separated by `,`, and `;`")
            return
        if kind is Kind.BAD_COMMENT:
            self.bad_comment(token)
            return
        statement = self.statement
        if statement is None:
            self.start(token)
        elif kind is Kind.SEMI:
            self.statement = None
            self.complete(statement)
        elif kind is Kind.COMMA:
            if statement.expect_comma:
                statement.expect_comma = False
            else:
                self.flag(statement, Code.MISSING_COMMA, token,
                          f"unexpected `,` after `{statement.last.text}`; a `,` goes only between two "
                          f"arguments, as in `{self.example(statement)}`")
            statement.last = token
        elif self.ends_statement(statement, token):
            self.statement = None
            self.missing_semicolon(statement.last)
            self.complete(statement, terminated=False)
            self.feed(token)
        else:
            if statement.expect_comma:
                self.flag(statement, Code.MISSING_COMMA, token,
                          f"missing `,` between `{statement.last.text}` and `{token.text}`; "
                          f"write `{self.example(statement)}`")
            statement.args.append(token)
            statement.last = token
            statement.expect_comma = True

    def start(self, token: Token) -> None:
        if token.kind is Kind.SEMI:
            return  # an empty statement, as in C
        statement = _Statement(head=token, skill=None, args=[], last=token)
        self.statement = statement
        if token.kind is not Kind.IDENT:
            self.flag(statement, Code.UNKNOWN_COMMAND, token,
                      f"a statement must start with a command, not `{token.text}`; "
                      f"the commands are {self.command_list()}")
            return
        skill = self.profile.skill(token.text)
        if skill is None and self.profile.skill(token.text.lower()) is not None:
            skill = self.profile.skill(token.text.lower())
            self.flag(statement, Code.KEYWORD_CASE, token,
                      f"commands are lowercase: write `{token.text.lower()}`, not `{token.text}`")
        elif skill is None:
            self.flag(statement, Code.UNKNOWN_COMMAND, token, self.unknown_command_message(token.text))
        statement.skill = skill

    def ends_statement(self, statement: _Statement, token: Token) -> bool:
        """Whether `token` must begin a new statement because a `;` is missing."""
        if token.kind not in _ARGUMENT_KINDS:
            return False
        is_command = token.kind is Kind.IDENT and self.profile.skill(token.text.lower()) is not None
        if statement.skill is None:
            return is_command
        complete = len(statement.args) >= len(statement.skill.params)
        if is_command and (complete or statement.expect_comma):
            return True
        # Newlines are free inside a statement, so a line break only ends a
        # statement that already has all its arguments.
        return complete and token.line > statement.last.line and statement.last.kind is not Kind.COMMA

    def complete(self, statement: _Statement, terminated: bool = True) -> None:
        skill = statement.skill
        if skill is None:
            return
        args = statement.args
        params = skill.params
        if len(args) != len(params) and not statement.broken:
            where = args[len(params)] if len(args) > len(params) else statement.head
            self.flag(statement, Code.PARAMETER_COUNT, where,
                      f"`{skill.keyword}` takes {self.describe_params(skill)} but got {len(args)}; "
                      f"write it as `{skill.signature}`, for example `{skill.example}`")
        values: list[Arg] = []
        for token, param in zip(args, params, strict=False):
            value = self.argument(statement, skill, token, param)
            if value is not None:
                values.append(value)
        if terminated and not statement.broken and len(values) == len(params):
            self.commands.append(Command(skill.keyword, tuple(values), statement.head.line,
                                         statement.head.column))

    # -- arguments and semantic checks -------------------------------------------------

    def argument(self, statement: _Statement, skill: Skill, token: Token, param: Param) -> Arg | None:
        if token.kind is Kind.BAD_NUMBER:
            self.flag(statement, Code.ILLEGAL_NUMBER, token, self.bad_number_message(token.text))
            return None
        if token.kind is Kind.BAD_IDENT:
            self.flag(statement, Code.ILLEGAL_IDENTIFIER, token, self.bad_name_message(token.text))
            return None
        if param.kind == "number":
            if token.kind is not Kind.NUMBER:
                self.flag(statement, Code.PARAMETER_TYPE, token,
                          f"`{skill.keyword}` expects a number ({self.describe_param(param)}) "
                          f"but `{token.text}` is a name; for example `{skill.example}`")
                return None
            return self.number(statement, skill, token, param)
        if token.kind is not Kind.IDENT:
            self.flag(statement, Code.PARAMETER_TYPE, token,
                      f"`{skill.keyword}` expects an object name but `{token.text}` is a number; "
                      f"for example `{skill.example}`")
            return None
        if self.known is not None and token.text not in self.known:
            self.flag(statement, Code.UNKNOWN_OBJECT, token, self.unknown_object_message(token.text))
            return None
        return ObjectRef(token.text)

    def number(self, statement: _Statement, skill: Skill, token: Token, param: Param) -> Arg | None:
        value = float(token.text)
        unit = f" {param.unit}" if param.unit else ""
        if param.is_coordinate:
            low, high = self.profile.workspace[str(param.axis)]
            if not low <= value <= high:
                self.flag(statement, Code.OUTSIDE_WORKSPACE, token,
                          f"{param.axis} = {token.text} is outside the workspace; {param.axis} must be "
                          f"between {low:g} and {high:g}{unit}")
                return None
            return Quantity(value, param.unit)
        if not value > 0:
            hint = (f"; to go the other way use `{skill.opposite} {token.text.lstrip('-+')};`"
                    if skill.opposite and value < 0 else "")
            self.flag(statement, Code.NOT_POSITIVE, token,
                      f"`{skill.keyword}` needs a positive {param.name}, got {token.text}{hint}")
            return None
        low = param.min if param.min is not None else 0.0
        high = param.max if param.max is not None else math.inf
        if not low <= value <= high:
            self.flag(statement, Code.OUT_OF_RANGE, token,
                      f"{param.name} {token.text}{unit} is out of range for `{skill.keyword}`: "
                      f"it must be between {low:g} and {high:g}{unit}")
            return None
        return Quantity(value, param.unit)

    # -- reporting ----------------------------------------------------------------------

    def report(self, code: Code, line: int, column: int, token: str, message: str) -> None:
        self.diagnostics.append(Diagnostic(code, line, column, token, message, self.lines.line_text(line)))

    def flag(self, statement: _Statement, code: Code, token: Token, message: str) -> None:
        if not (statement.broken and not code.is_semantic):
            self.report(code, token.line, token.column, token.text, message)
        statement.broken = True

    def missing_semicolon(self, last: Token) -> None:
        self.diagnostics.append(Diagnostic(
            Code.MISSING_SEMICOLON, last.line, last.column, last.text,
            f"missing `;` after `{last.text}`; every statement ends with `;`",
            self.lines.line_text(last.line)))

    def bad_comment(self, token: Token) -> None:
        if token.text.startswith("/*"):
            message = "this `/*` comment is never closed; end it with `*/`"
        else:
            message = "`/` does not start a comment; write `//` for a line comment or `/* ... */`"
        self.report(Code.BAD_COMMENT, token.line, token.column, token.text[:2].rstrip(), message)

    # -- wording helpers ----------------------------------------------------------------

    def unknown_command_message(self, word: str) -> str:
        target = self.profile.alias_target(word)
        if target is None:
            close = difflib.get_close_matches(word.lower(), self.profile.keywords, n=1, cutoff=0.6)
            target = close[0] if close else None
        if target is not None:
            skill = self.profile.skill(target)
            assert skill is not None
            return (f"`{word}` is not a command; did you mean `{target}`? "
                    f"(`{skill.signature}`: {skill.description[0].lower()}{skill.description[1:]})")
        return f"`{word}` is not a command; the commands are {self.command_list()}"

    def unknown_object_message(self, name: str) -> str:
        known = sorted(self.known or ())
        close = difflib.get_close_matches(name, known, n=1, cutoff=0.6)
        if close:
            return f"`{name}` is not an object this robot knows; did you mean `{close[0]}`?"
        perceive = self.profile.bound_to("perceive_objects")
        listed = ", ".join(f"`{k}`" for k in known) or (
            f"none yet (use `{perceive.signature}` first)" if perceive is not None else "none")
        return f"`{name}` is not an object this robot knows; the known objects are {listed}"

    def command_list(self) -> str:
        return ", ".join(f"`{k}`" for k in self.profile.keywords)

    def example(self, statement: _Statement) -> str:
        if statement.skill is not None:
            return statement.skill.example
        # An unknown word: show a statement with arguments, the comma's place.
        return max(self.profile.skills, key=lambda s: len(s.params)).example

    @staticmethod
    def describe_param(param: Param) -> str:
        return f"{param.name} in {param.unit}" if param.unit else param.name

    def describe_params(self, skill: Skill) -> str:
        if not skill.params:
            return "no arguments"
        kinds = ["an object" if p.kind == "object" else "a number" for p in skill.params]
        count = len(kinds)
        return f"{count} argument{'s' if count > 1 else ''} ({', '.join(kinds)})"

    def bad_number_message(self, text: str) -> str:
        sign, digits = ("-" if text.startswith("-") else ""), text.lstrip("-+")
        base = {"x": 16, "b": 2, "o": 8}.get(digits[1:2].lower()) if digits.startswith("0") else None
        if base is not None:
            kind = {16: "hexadecimal", 2: "binary", 8: "octal"}[base]
            try:
                decimal = f"write it in decimal, `{sign}{int(digits[2:], base)}`"
            except ValueError:
                decimal = "write it as a plain decimal"
            return f"`{text}` is not an RSL number: RSL has no C {kind} numbers; {decimal}"
        if digits[:1] == "0" and digits.isdigit():
            return (f"`{text}` is not an RSL number: a leading 0 makes it octal in C, which RSL does not have; "
                    f"write `{sign}{digits.lstrip('0') or '0'}`")
        return (f"`{text}` is not a number; write a plain decimal such as "
                f"`{self.number_hint(text)}` (no units, one decimal point)")

    @staticmethod
    def bad_name_message(text: str) -> str:
        if text.isascii():
            fixed = text.lstrip("0123456789") or "object"
            return f"`{text}` is not a valid name: names start with a letter or `_`; did you mean `{fixed}`?"
        # NFKD splits `é` into `e` and an accent and turns `²` into `2`; what is left over is dropped.
        fixed = "".join(c for c in unicodedata.normalize("NFKD", text) if c.isascii() and (c.isalnum() or c == "_"))
        advice = f"write `{fixed}` instead" if is_identifier(fixed) else "use an ASCII name"
        return f"`{text}` is not a valid name: names use only ASCII letters, digits and `_`; {advice}"

    @staticmethod
    def number_hint(text: str) -> str:
        digits = text.lstrip("-+")
        head, _, tail = digits.partition(".")
        head = "".join(ch for ch in head if ch.isdigit()) or "0"
        tail = "".join(ch for ch in tail.split(".")[0] if ch.isdigit())
        return f"{head}.{tail}" if tail else head
