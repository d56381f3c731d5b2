"""The world's state: the tables' column layouts (one place), slots with free lists and revisions, growth
and snapshots."""
