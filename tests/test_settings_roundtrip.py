"""Settings survive their own rewrite: whatever a settings file held that was read, the window's
rewrite (on m or a resize) writes TOML that is read back to the same settings."""

import string

from hypothesis import given, settings
from hypothesis import strategies as st

from armgame.ui.settings import Settings, check_muscle_keys, from_toml, save


def test_keys_with_a_quote_or_a_backslash_survive_the_rewrite(tmp_path):
    path = tmp_path / "settings.toml"
    path.write_text("keys = 'a,\",\\,d'\n")  # a literal string: a quote and a backslash among the keys
    first = from_toml(path.read_bytes(), str(path))
    assert first.keys == 'a,",\\,d'
    save(first.with_changes(mute=True), path)  # what pressing m does
    assert from_toml(path.read_bytes(), str(path)) == first.with_changes(mute=True)


KEY = st.text(alphabet=st.characters(blacklist_categories=("Cs",), blacklist_characters=","), min_size=1, max_size=3)


@settings(max_examples=200, deadline=None)
@given(keys=st.lists(KEY, min_size=4, max_size=4, unique=True), mute=st.booleans(),
       size=st.none() | st.tuples(st.integers(320, 10000), st.integers(320, 10000)))
def test_any_accepted_settings_round_trip(keys, mute, size):
    text = ",".join(keys)
    try:
        check_muscle_keys(text)
    except ValueError:
        return  # not settings the reader accepts: nothing to write back
    original = Settings(keys=text, mute=mute, size=size)
    assert from_toml(original.to_toml().encode(), "rewrite") == original


@given(st.text(alphabet=string.printable, max_size=40))
def test_the_writer_never_writes_what_the_reader_refuses_as_toml(text):
    import tomllib

    assert tomllib.loads(Settings(keys=text).to_toml())["keys"] == text
