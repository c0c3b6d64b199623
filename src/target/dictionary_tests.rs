use super::*;
use crate::synth::rng::Rng;

/// OpenCV 4.14's marker counts, marker sizes and maxCorrectionBits
/// (`cv2.aruco.getPredefinedDictionary(d)`: `bytesList.shape[0]`,
/// `markerSize`, `maxCorrectionBits`), written out independently of the
/// generated file.
const OPENCV: [(Dictionary, usize, usize, u32); 22] = [
    (Dictionary::DICT_4X4_50, 50, 4, 1),
    (Dictionary::DICT_4X4_100, 100, 4, 1),
    (Dictionary::DICT_4X4_250, 250, 4, 1),
    (Dictionary::DICT_4X4_1000, 1000, 4, 0),
    (Dictionary::DICT_5X5_50, 50, 5, 3),
    (Dictionary::DICT_5X5_100, 100, 5, 3),
    (Dictionary::DICT_5X5_250, 250, 5, 2),
    (Dictionary::DICT_5X5_1000, 1000, 5, 2),
    (Dictionary::DICT_6X6_50, 50, 6, 6),
    (Dictionary::DICT_6X6_100, 100, 6, 5),
    (Dictionary::DICT_6X6_250, 250, 6, 5),
    (Dictionary::DICT_6X6_1000, 1000, 6, 4),
    (Dictionary::DICT_7X7_50, 50, 7, 9),
    (Dictionary::DICT_7X7_100, 100, 7, 8),
    (Dictionary::DICT_7X7_250, 250, 7, 8),
    (Dictionary::DICT_7X7_1000, 1000, 7, 6),
    (Dictionary::DICT_ARUCO_ORIGINAL, 1024, 5, 1),
    (Dictionary::DICT_APRILTAG_16h5, 30, 4, 2),
    (Dictionary::DICT_APRILTAG_25h9, 35, 5, 4),
    (Dictionary::DICT_APRILTAG_36h10, 2320, 6, 4),
    (Dictionary::DICT_APRILTAG_36h11, 587, 6, 5),
    (Dictionary::DICT_ARUCO_MIP_36h12, 250, 6, 5),
];

#[test]
fn every_dictionary_has_opencvs_counts_sizes_and_correction() {
    for (d, count, size, correction) in OPENCV {
        assert_eq!(d.len(), count, "{} markers", d.name());
        assert_eq!(d.marker_bits(), size, "{} bits per side", d.name());
        assert_eq!(
            d.max_correction_bits(),
            correction,
            "{} correction",
            d.name()
        );
        assert_eq!(Dictionary::from_name(d.name()).unwrap(), d);
    }
}

#[test]
fn apriltag_36h11_is_the_apriltag_projects_code() {
    // AprilTag's tag36h11 code 0 is 0xd5d628584 with the first bit the one
    // OpenCV draws at the bottom right: OpenCV's row-major bits reversed.
    let code = Dictionary::DICT_APRILTAG_36h11.code(0).unwrap();
    assert_eq!(code.reverse_bits() >> (64 - 36), 0xd5d628584);
    // The small dictionaries are the first markers of the 1000 ones.
    for id in 0..250 {
        assert_eq!(
            Dictionary::DICT_7X7_250.code(id),
            Dictionary::DICT_7X7_1000.code(id)
        );
    }
}

#[test]
fn unknown_dictionary_lists_the_known_ones() {
    let e = Dictionary::from_name("DICT_8X8_50")
        .unwrap_err()
        .to_string();
    assert!(e.contains("unknown marker dictionary 'DICT_8X8_50'"), "{e}");
    assert!(e.contains("DICT_4X4_50, DICT_4X4_100"), "{e}");
    assert!(e.contains("DICT_ARUCO_MIP_36h12"), "{e}");
    assert_eq!(
        Dictionary::from_name("dict_apriltag_36H11").unwrap(),
        Dictionary::DICT_APRILTAG_36h11
    );
}

#[test]
fn rotation_four_times_is_identity_and_matches_a_hand_turned_grid() {
    // 2 x 2: [a b; c d] turned clockwise is [c a; d b].
    assert_eq!(rotate_clockwise(0b1000, 2), 0b0100);
    assert_eq!(rotate_clockwise(0b0001, 2), 0b0010);
    let c = Dictionary::DICT_7X7_50.code(3).unwrap();
    let mut r = c;
    for _ in 0..4 {
        r = rotate_clockwise(r, 7);
    }
    assert_eq!(r, c);
}

#[test]
fn every_marker_decodes_in_every_rotation_with_the_documented_bit_errors() {
    let mut rng = Rng::new(18);
    for d in Dictionary::ALL {
        let n = d.marker_bits();
        let max = d.max_correction_bits();
        for id in 0..d.len() {
            let code = d.code(id).unwrap();
            let mut turned = code;
            for rotation in 0..4 {
                // Flip exactly `max` distinct bits at random.
                let mut read = turned;
                let mut flipped = 0;
                while flipped < max {
                    let bit = 1u64 << rng.below(n * n);
                    if (read ^ turned) & bit == 0 {
                        read ^= bit;
                        flipped += 1;
                    }
                }
                let got = d.decode(read, max);
                assert_eq!(
                    got,
                    Some(Decoded {
                        id,
                        rotation,
                        bit_errors: max
                    }),
                    "{} marker {id} turned {rotation} times with {max} bit errors",
                    d.name()
                );
                turned = rotate_clockwise(turned, n);
            }
        }
    }
}

#[test]
fn one_bit_past_the_limit_is_not_accepted_as_that_marker() {
    let d = Dictionary::DICT_5X5_100;
    let code = d.code(7).unwrap();
    let read = code ^ 0b1111; // 4 errors, the limit is 3
    assert!(d.decode(read, 3).map_or(true, |m| m.id != 7));
}
