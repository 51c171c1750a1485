"""Files in and out: TOML inputs (`toml`), ecgpack basis files (`ecgpack`), basis.json
(`basis_json`), either told by its content (`stored`) and the atomic writer every output goes
through (`files`). Import the module you need; this package imports none of them."""
