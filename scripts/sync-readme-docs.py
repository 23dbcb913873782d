#!/usr/bin/env python3
"""copies the reference docs into README.md between their markers, so the README's
robot sections and world-file reference never drift from docs/.

  <!-- begin robots -->        docs/robots/*.md (headings demoted one level)
  <!-- begin world-file -->    docs/world-file.md
each block ends at the matching <!-- end ... --> marker."""
import pathlib
import posixpath
import re

root = pathlib.Path(__file__).resolve().parent.parent
readme = root / "README.md"


def readme_links(text, base="docs"):
    """links between docs (`](effects.md)`, `](../policies.md)` in docs/robots/) point from the
    README to the file they name, relative to `base`, the folder of the doc they are in."""
    return re.sub(r"\]\((?![a-z]+:|/|#|docs/)([^)#]+\.(?:md|png))",
                  lambda m: "](" + posixpath.normpath(posixpath.join(base, m.group(1))), text)


def demote(text):
    return re.sub(r"^(#+) ", lambda m: "#" + m.group(1) + " ", text, flags=re.M)


robots = ["rover", "quadruped", "quadruped_arm", "quadrotor", "arm"]
parts = []
for name in robots:
    p = root / "docs" / "robots" / f"{name}.md"
    if p.exists():
        parts.append(readme_links(demote(p.read_text().strip()), "docs/robots"))
blocks = {
    "robots": "## Robots\n\nEach bundled robot has a model in `worlds/models/`, an example world in "
    "`worlds/`, and a controller configured in that world.\n\n" + "\n\n".join(parts),
    "world-file": readme_links((root / "docs" / "world-file.md").read_text().strip()),
}
text = readme.read_text()
for key, body in blocks.items():
    begin, end = f"<!-- begin {key} -->", f"<!-- end {key} -->"
    if begin not in text:
        text = text.rstrip() + f"\n\n{begin}\n{end}\n"
    pre, rest = text.split(begin, 1)
    _, post = rest.split(end, 1)
    text = f"{pre}{begin}\n{body}\n{end}{post}"
readme.write_text(text)
