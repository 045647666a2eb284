"""moo.tables: the CSV, Markdown and LaTeX writers, read back with independent parsers (csv, plain splitting)."""

import csv
import io

import pytest

from moo.tables import latex_tabular, markdown_table, write_csv


def test_csv_round_trips_through_the_csv_reader(tmp_path):
    rows = [["a", 1, 2.5, True], ["with, comma", 'quote "q"', "", None]]
    text = write_csv(["name", "n", "x", "flag"], rows, tmp_path / "t.csv")
    assert (tmp_path / "t.csv").read_bytes() == text.encode()
    assert text.startswith("name,n,x,flag\n") and "\r" not in text
    back = list(csv.reader(io.StringIO(text)))
    assert back == [["name", "n", "x", "flag"], ["a", "1", "2.5", "True"], ["with, comma", 'quote "q"', "", ""]]
    crlf = write_csv(["a"], [[1]], lineterminator="\r\n")
    assert crlf == "a\r\n1\r\n"


def test_markdown_table_cells_and_alignment():
    text = markdown_table(["k", "v", "w"], [["x", 1, ""], ["y", 2.5, "z"]], align="lrc")
    lines = text.split("\n")
    assert lines[1] == "|---|---:|:---:|"
    cells = [[c.strip() for c in line.strip("|").split("|")] for line in lines[:1] + lines[2:]]
    assert cells == [["k", "v", "w"], ["x", "1", ""], ["y", "2.5", "z"]]
    assert markdown_table(["a"], []) == "| a |\n|---|"
    with pytest.raises(ValueError, match="align"):
        markdown_table(["a", "b"], [], align="l")
    with pytest.raises(ValueError, match="2 cells"):
        markdown_table(["a", "b"], [[1]])


def test_latex_tabular_groups_and_rules():
    text = latex_tabular("c c", [r"a & b \\"], [[[1, 2], [3, 4]], [["", 5]]])
    lines = text.split("\n")
    assert lines[0] == r"\begin{tabular}{c c}" and lines[-1] == r"\end{tabular}"
    assert lines.count(r"\hline") == 4                       # top, under the header, after each group
    assert lines[5:7] == [r"3 & 4 \\", r"\hline"] and lines[7] == r" & 5 \\"
