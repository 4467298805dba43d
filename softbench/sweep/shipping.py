"""Cache files through Ray's object store, so that no node needs shared storage.

A build returns its cache files' bytes, named by their place under the data home; whoever needs
the build (a worker about to build or evaluate from it, and the driver, whose data home so ends up
holding everything the sweep made) writes the ones its own data home lacks before going on. With
a data home on shared storage every file is there already and nothing is written.
"""

from softbench import storage

Files = dict[str, bytes]  # Path relative to the data home -> the file's bytes.


def read(names: tuple[str, ...]) -> Files:
  """The files ``names`` (relative to the data home, in that order) as they are in it."""
  home = storage.softbench_home()
  return {name: (home / name).read_bytes() for name in names}


def write_missing(*shipped: Files) -> None:
  """Writes every file of ``shipped`` that the data home lacks, in order and atomically, so that
  a reader that finds a build's last file finds the files before it too."""
  home = storage.softbench_home()
  for files in shipped:
    for name, content in files.items():
      if not (home / name).exists():
        storage.write_atomically(home / name, content)
