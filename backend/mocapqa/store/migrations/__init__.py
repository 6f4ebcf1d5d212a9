"""The schema's migration history (Alembic): ``env.py`` and one script per revision in
``versions/``. The store runs them when it opens a database (:mod:`mocapqa.store.upgrade`);
docs/database.md says how to add one."""
