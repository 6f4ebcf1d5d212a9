"""One Alembic revision per schema change, oldest first (``v0001`` is the first released
schema)."""
