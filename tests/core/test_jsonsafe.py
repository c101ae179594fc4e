"""JSON nesting bounded before the recursive parser sees it (runs on both interpreters)."""

import unittest

from obsw import jsonsafe
from obsw.jsonsafe import JsonDepthError, check_depth


class TestCheckDepth(unittest.TestCase):
    def test_at_the_limit_passes_and_one_more_fails(self):
        check_depth("[" * 4 + "]" * 4, 4)
        with self.assertRaises(JsonDepthError) as cm:
            check_depth('{"a":' * 5 + "1" + "}" * 5, 4)
        self.assertEqual((cm.exception.depth, cm.exception.limit), (5, 4))

    def test_depth_is_the_deepest_open_not_the_count(self):
        check_depth("[[],[],[[]],[]]" * 100, 3)

    def test_brackets_in_strings_do_not_count(self):
        check_depth('["[[[[", "{{{{"]', 1)
        check_depth(b'["\\"[[[[", "\\\\", "{"]', 1)

    def test_escaped_quote_does_not_end_a_string(self):
        with self.assertRaises(JsonDepthError):
            check_depth('["\\\\", [[]]]', 2)  # the string is one backslash: [[]] counts
        check_depth('["\\"[[", "]]"]', 1)  # the first string holds \\" and two brackets

    def test_unterminated_string_is_left_to_the_parser(self):
        check_depth('["[[[[', 1)
        with self.assertRaises(ValueError):
            jsonsafe.loads('["[[[[', 1)

    def test_str_and_bytes_alike(self):
        text = '{"t\u00e9mp\u00e9rature": [1, 2, {"x": "[\u2103"}]}'
        self.assertEqual(jsonsafe.loads(text), jsonsafe.loads(text.encode()))
        with self.assertRaises(JsonDepthError):
            jsonsafe.loads(text.encode(), 2)

    def test_every_failure_is_a_value_error(self):
        for bad in (b"\xff[1]", "[" * 100, "[1,", b"[" * 100):
            with self.assertRaises(ValueError):
                jsonsafe.loads(bad)


if __name__ == "__main__":
    unittest.main()
