"""Training and caching of learned models: forward models shared by every agent that reads the
same view (``forward_models``) and the paper's protocols on softbench data (``protocols``)."""
