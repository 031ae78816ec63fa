"""An exam as a Moodle XML quiz: one numerical question per variant and value asked.

Each question's text gives the variant's data (its drawn values, with units) and asks one
value; its answer is pam2exu's, with an absolute tolerance of ``tolerance`` · |answer|
(Moodle's numerical tolerance is absolute), and at least ``tolerance`` · 1e-3 of the
largest answer to that question over the variants, so that an answer of zero can be met.
"""
from __future__ import annotations

import html
import xml.etree.ElementTree as ET

#: the smallest tolerance, as a fraction of the largest answer to the same question
FLOOR = 1e-3


def tolerance_of(value: float, largest: float, relative: float) -> float:
    """Moodle's absolute tolerance of an answer: relative · max(|value|, FLOOR · largest)."""
    return relative * max(abs(value), FLOOR * largest)


def data_text(exam, variant) -> str:
    """The variant's data (``exam.data_lines``), one line each (HTML)."""
    from . import data_lines
    return "<br/>".join(html.escape(line) for line in data_lines(exam, variant))


def quiz(exam) -> str:
    """The quiz's XML text."""
    root = ET.Element("quiz")
    category = ET.SubElement(root, "question", type="category")
    ET.SubElement(ET.SubElement(category, "category"), "text").text = \
        f"$course$/pam2exu/{exam.source}"
    largest = {q: max(abs(v.answers[q]) for v in exam.variants) for q in exam.questions}
    for variant in exam.variants:
        for j, q in enumerate(exam.questions, start=1):
            value = variant.answers[q]
            unit = variant.units.get(q.output, "")
            question = ET.SubElement(root, "question", type="numerical")
            ET.SubElement(ET.SubElement(question, "name"), "text").text = \
                f"variant {variant.number}, question {j}: {q}"
            text = ET.SubElement(question, "questiontext", format="html")
            ET.SubElement(text, "text").text = (
                f"<p>Mechanism '{html.escape(variant.model.name)}', variant "
                f"{variant.number}, {exam.analysis} analysis.</p>"
                f"<p>{data_text(exam, variant)}</p>"
                f"<p>Give {q.output} at t = {q.t:g} s" + (f" in {unit}" if unit else "")
                + ".</p>")
            answer = ET.SubElement(question, "answer", fraction="100")
            ET.SubElement(answer, "text").text = repr(value)
            ET.SubElement(answer, "tolerance").text = repr(
                tolerance_of(value, largest[q], exam.tolerance))
            if unit:
                units = ET.SubElement(question, "units")
                u = ET.SubElement(units, "unit")
                ET.SubElement(u, "multiplier").text = "1"
                ET.SubElement(u, "unit_name").text = unit
                ET.SubElement(question, "unitgradingtype").text = "0"
                ET.SubElement(question, "showunits").text = "3"
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") \
        + "\n"
