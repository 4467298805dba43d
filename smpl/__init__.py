"""SMPL: progressive LSTM networks, forward models and closed-loop training for modular soft
arms."""
