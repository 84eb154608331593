"""An example signorini-bench plugin: each module registers one unit when imported (its entry
point names the module)."""
