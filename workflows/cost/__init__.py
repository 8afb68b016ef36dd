"""What MD fidelity costs: the speed/accuracy trade study and the benchmark."""
