"""A table of figures as every page (``text``, ``markdown_page``, ``html_page``) shows it."""

import dataclasses


@dataclasses.dataclass(frozen=True)
class Table:
  """A caption, a header and rows of cells (strings), the first ``label_columns`` of them labels,
  the others figures; ``paper_rows``: the indices of the rows that hold the paper's values."""

  caption: str
  header: tuple[str, ...]
  rows: tuple[tuple[str, ...], ...]
  label_columns: int
  paper_rows: tuple[int, ...] = ()
