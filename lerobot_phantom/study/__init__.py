"""``lerobot-phantom-study``: the paper's whole loop (collect -> train -> Table-3 sweep -> adversarial LoRA and a
clean control -> sweeps -> Table-5 report) as resumable stages that call the package's own CLIs."""
