"""Continual learning as a benchmark: strategies (``strategies``) learn streams of changing arms
(``streams``) stage by stage (``learning``), scored with the field's figures (``metrics``) by
``softbench run --protocol continual`` (``softbench.runners.continual_stream``)."""
