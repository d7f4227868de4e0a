"""Scheme texts of the two mechanisms the tests declare most often, with chosen dimensions.

``header`` goes after the name and input (e.g. an ``output`` or ``range_deg`` line); ``tail`` is
appended (e.g. a ``[dynamics]`` section); ``assembly`` is the body of ``[assembly.B]``.
"""

from __future__ import annotations


def four_bar_toml(crank, coupler, rocker, ground, assembly='left_of = ["A", "C"]', *,
                  name="four_bar", header="", tail="") -> str:
    """Four-bar O-A-B-C: pivots O = (0, 0) and C = (ground, 0), crank OA, coupler AB, rocker CB."""
    return f"""
name = "{name}"
input = "1"
{header}
[links.0]
points = {{ O = [0.0, 0.0], C = [{ground!r}, 0.0] }}
[links.1]
line = ["O", "A"]
length = {crank!r}
[links.2]
line = ["A", "B"]
length = {coupler!r}
[links.3]
line = ["C", "B"]
length = {rocker!r}
[pairs.O]
links = ["0", "1"]
[pairs.A]
links = ["1", "2"]
[pairs.B]
links = ["2", "3"]
[pairs.C]
links = ["3", "0"]
[assembly.B]
{assembly}
{tail}"""


def slider_crank_toml(crank, rod, assembly='from = "A"\ntowards_deg = 0', *, name="slider_crank",
                      header="", tail="", offset=0.0) -> str:
    """Slider-crank: crank OA about O = (0, 0), rod AB, slider B on the guide ``slide`` along x at
    y = ``offset`` (central by default)."""
    return f"""
name = "{name}"
input = "1"
{header}
[links.0]
points = {{ O = [0.0, 0.0] }}
guides.slide = {{ through = [0.0, {offset!r}], angle_deg = 0 }}
[links.1]
line = ["O", "A"]
length = {crank!r}
[links.2]
line = ["A", "B"]
length = {rod!r}
[links.3]
points.B = [0.0, 0.0]
[pairs.O]
links = ["0", "1"]
[pairs.A]
links = ["1", "2"]
[pairs.B]
links = ["2", "3"]
[pairs.slide]
kind = "P"
links = ["0", "3"]
guide = "slide"
at = "B"
[assembly.B]
{assembly}
{tail}"""
