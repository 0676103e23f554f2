"""Maps as numpy arrays: map_server's values, round trips through files, bad input."""
import tempfile
import unittest
from pathlib import Path

import numpy as np

import fleetmap


class MapsTest(unittest.TestCase):
    def test_a_builtin_map_is_a_map_server_image(self):
        office = fleetmap.load_map("office")
        image = office.image
        self.assertEqual(image.dtype, np.uint8)
        self.assertEqual(image.shape, (office.height, office.width))
        self.assertTrue(set(np.unique(image)) <= {0, 205, 254})
        self.assertEqual(int((image == 254).sum()), office.free_cells)
        self.assertEqual(int((image == 0).sum()), office.occupied_cells)
        self.assertAlmostEqual(office.resolution, 0.1)  # maps/office.yaml

    def test_an_array_becomes_a_map_and_back(self):
        image = np.full((30, 40), 205, np.uint8)
        image[5:25, 5:35] = 254
        image[5, 5:35] = 0
        m = fleetmap.Map.from_image(image, resolution=0.1, origin=(1.0, -2.0, 0.0))
        self.assertEqual((m.width, m.height), (40, 30))
        self.assertEqual(m.origin, (1.0, -2.0, 0.0))
        np.testing.assert_array_equal(m.image, image)
        # The top row of the image is the map's last row: a wall along the top edge of the room.
        self.assertEqual(m.occupied_cells, 30)

    def test_saved_maps_load_back_unchanged(self):
        office = fleetmap.load_map("office")
        with tempfile.TemporaryDirectory() as tmp:
            for name in ("office.yaml", "office.png", "office.pgm"):
                path = Path(tmp) / name
                fleetmap.save_map(office, path)
                again = fleetmap.load_map(str(path))
                np.testing.assert_array_equal(again.image, office.image, err_msg=name)
            self.assertTrue((Path(tmp) / "office.yaml").read_text().startswith("image: office.pgm"))

    def test_bad_input_names_the_problem(self):
        with self.assertRaisesRegex(ValueError, "2-D array"):
            fleetmap.Map.from_image(np.zeros((4, 4, 3), np.uint8))
        with self.assertRaisesRegex(ValueError, "no-such-map"):
            fleetmap.load_map("no-such-map")


if __name__ == "__main__":
    unittest.main()
