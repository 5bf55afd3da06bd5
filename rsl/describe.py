"""Human- and LLM-readable descriptions of a profile's RSL, generated from the profile."""

from __future__ import annotations

from rsl.profile import Param, Profile, Skill


def _param_text(param: Param) -> str:
    if param.kind == "object":
        return f"{param.name.upper()} is an object name (a C identifier such as cup or red_ball)"
    if param.is_coordinate:
        return (f"{param.name.upper()} is a coordinate in {param.unit}, from {param.min:g} to {param.max:g}; "
                "zero and negative values are allowed")
    return f"{param.name.upper()} in {param.unit}, from {param.min:g} to {param.max:g}"


def _skill_line(skill: Skill) -> str:
    details = "; ".join(_param_text(p) for p in skill.params)
    details = f" {details}." if details else ""
    return f"- `{skill.signature}` {skill.description}{details} Example: `{skill.example}`"


def language_description(profile: Profile) -> str:
    """The RSL reference the LLM sees in its system prompt."""
    lines = [
        f"RSL (Robot Skill Language) programs control {profile.description}.",
        "A program is a list of statements, one per line. Each statement is a lowercase command, "
        "its arguments separated by `, `, and a `;`.",
        "Distances are in metres and angles in radians (90 degrees = 1.5708, 180 degrees = 3.1416). "
        "Numbers are plain decimals such as 2, 0.5 or 1.5708; amounts are always positive, "
        "and the command says the direction.",
        f"At most {profile.max_statements} statements. The robot starts at x=0, y=0 facing +x; "
        "+y is to its left.",
        "",
        "Commands:",
        *(_skill_line(s) for s in profile.skills),
    ]
    if profile.conventions:
        lines += ["", "Conventions for vague amounts:"]
        lines += [f"- \"{c.phrase}\": {c.meaning}" + (f"; \"{c.task}\" -> `{c.program}`" if c.task else "")
                  for c in profile.conventions]
    return "\n".join(lines) + "\n"


def _coordinates(profile: Profile) -> str:
    takes = [f"`{s.keyword}`" for s in profile.skills if any(p.is_coordinate for p in s.params)]
    if not takes:
        return "and none may be zero or negative."
    return f"only {' and '.join(takes)} coordinates may be zero or negative."


def markdown_reference(profile: Profile) -> str:
    """docs/language.md: the reference for people, from the same source."""
    rows = []
    for skill in profile.skills:
        params = "; ".join(_param_text(p) for p in skill.params) or "none"
        does = skill.binding.describe() if skill.binding is not None else "no binding: runs on no robot"
        rows.append(f"| `{skill.signature}` | {skill.description} | {params} | {does} | `{skill.example}` |")
    conventions = [f"| {c.phrase} | {c.meaning} | `{c.program}` |" for c in profile.conventions]
    ws = profile.workspace
    return "\n".join([
        f"# RSL reference for the `{profile.name}` robot",
        "",
        "<!-- Generated from the robot profile by `nrtrans profile show --format markdown`. "
        "Do not edit by hand. -->",
        "",
        f"This robot is {profile.description}.",
        "",
        "## Statements",
        "",
        "Each statement is a lowercase command, its arguments separated by `,`, and `;`. "
        "Whitespace and newlines are free. Comments are `// to the end of the line` and `/* blocks */`. "
        "Numbers are C-style decimals (`2`, `0.5`, `.5`, `1e-1`), not C's hexadecimal `0x10` or octal `010`; "
        f"amounts must be positive, {_coordinates(profile)} "
        "Object names are ASCII C identifiers (letters, digits and `_`).",
        "",
        "| statement | what it does | parameters | binding | example |",
        "|---|---|---|---|---|",
        *rows,
        "",
        "The binding is what the statement makes the robot do: a robot primitive that every backend "
        "implements, or a ROS 2 topic, service or joint trajectory (docs/skills.md).",
        "",
        "## Limits",
        "",
        f"- At most {profile.max_statements} statements in a program.",
        f"- Workspace: x from {ws['x'][0]:g} to {ws['x'][1]:g} m, y from {ws['y'][0]:g} to {ws['y'][1]:g} m. "
        "The robot starts at (0, 0) facing +x; +y is to its left.",
        "",
        "## What vague words mean",
        "",
        "| phrase | meaning | example |",
        "|---|---|---|",
        *conventions,
        "",
        "## Errors",
        "",
        "`nrtrans check FILE` reports every error with a stable code, its line and column, the token, "
        "and what to do. Codes E001-E010 are syntax errors, E101-E105 semantic ones "
        "(range, sign, workspace, unknown object, program length). E201 comes from the translator, "
        "not the compiler: the words were not read as a task for this robot.",
        "",
    ])
