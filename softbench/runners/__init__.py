"""Everything that runs work and writes records: ``softbench run`` (``run``), Exp1S in physics
(``continual``), ``softbench retrain`` (``retrain``), adaptive module activation (``adaptive``),
seeds in worker processes (``parallel_seeds``), the saving of a record (``saving``), and the
zoo's catalogue of what a setting caches (``zoo_catalogue``) and ``zoo verify``
(``zoo_verification``). The leaderboard and the records only read what these write."""
