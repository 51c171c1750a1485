"""Files in and out: TOML inputs (`toml`), ecgpack basis files (`ecgpack`) and basis.json
(`basis_json`). Import the module you need; this package imports none of them."""
