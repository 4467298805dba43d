"""Training and caching of learned models, with no agent or runner in sight: checkpoints named by
everything their weights depend on (``checkpoints``), an inverse model trained in closed loop
through frozen forward models (``inverse``), the forward models shared by every agent that reads
the same view (``forward_models``), the paper's protocols on softbench data (``protocols``) and
Exp1S's network (``exp1s``). A continual-learning strategy belongs here, one file each."""
