use super::*;

#[test]
fn default_config_is_valid_and_toml_like_round_trip() {
    let c = StreetConfig::default();
    c.validate().unwrap();
    let json = serde_json::to_string(&c).unwrap();
    let back: StreetConfig = serde_json::from_str(&json).unwrap();
    assert_eq!(back, c);
    let partial: StreetConfig = serde_json::from_str(r#"{"speed": 8.0}"#).unwrap();
    assert_eq!(partial.speed, 8.0);
    assert_eq!(partial.lidar, LidarConfig::default());
    assert!(serde_json::from_str::<StreetConfig>(r#"{"sped": 8.0}"#).is_err());
}

fn distance_to_segment(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let t = (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
    (p[0] - a[0] - t * dx).hypot(p[1] - a[1] - t * dy)
}

#[test]
fn walls_stay_clear_of_the_ego_path_and_face_the_street() {
    // 15 s: the first two turns of the default route.
    let sim = StreetSimulator::new(&StreetConfig::default(), 150, 4).unwrap();
    let street = sim.street();
    assert_eq!(street.segments.len(), 4);
    assert!(street.walls.len() > 20, "{}", street.walls.len());
    for w in &street.walls {
        let v = w.vertices();
        for k in 0..sim.frames() {
            let e = sim.ego(k);
            let d = distance_to_segment([e.x, e.y], [v[0][0], v[0][1]], [v[1][0], v[1][1]]);
            assert!(d > 6.0, "wall {} is {d} m from the ego at frame {k}", w.id);
        }
        assert!(w.length >= 5.0 && (6.0..=15.0).contains(&w.height), "{w:?}");
        // The normal points to the centreline of the wall's own segment.
        let mid = [0.5 * (v[0][0] + v[1][0]), 0.5 * (v[0][1] + v[1][1])];
        let seg = street.segments.iter().find(|s| s.dir == w.along).unwrap();
        let s = (mid[0] - seg.point[0]) * seg.dir[0] + (mid[1] - seg.point[1]) * seg.dir[1];
        let c = seg.at(s, 0.0);
        let side = w.normal[0] * c[0] + w.normal[1] * c[1] + w.offset();
        assert!((side - 12.0).abs() < 1e-6, "wall {}: {side}", w.id);
    }
}

#[test]
fn objects_keep_clear_of_the_ego_and_move_as_configured() {
    let config = StreetConfig::default();
    let sim = StreetSimulator::new(&config, 100, 8).unwrap();
    let street = sim.street();
    let t = &config.traffic;
    assert_eq!(
        street.objects.len(),
        t.parked_cars + t.moving_cars + t.pedestrians
    );
    let truth = sim.truth();
    for o in &truth.objects {
        assert!(!o.states.is_empty() || o.kind != ObjectKind::ParkedCar);
        for s in &o.states {
            let e = sim.ego(s.frame);
            let gap = (s.position[0] - e.x).hypot(s.position[1] - e.y);
            assert!(gap > 4.0, "object {} {gap} m from the ego", o.id);
            let v = s.velocity[0].hypot(s.velocity[1]);
            let ok = match o.kind {
                ObjectKind::ParkedCar => v == 0.0,
                ObjectKind::Car => (5.0..=12.0).contains(&v),
                ObjectKind::Pedestrian => (1.2..=1.4).contains(&v),
            };
            assert!(ok, "{o:?}");
            // The heading is along the velocity.
            if v > 0.0 {
                let heading = s.velocity[1].atan2(s.velocity[0]);
                assert!(crate::geometry::wrap_angle(heading - s.yaw).abs() < 1e-9);
            }
        }
        // Consecutive states move by velocity × frame period.
        for w in o.states.windows(2) {
            if w[1].frame == w[0].frame + 1 {
                for i in 0..2 {
                    let step = w[1].position[i] - w[0].position[i];
                    assert!((step - 0.1 * w[0].velocity[i]).abs() < 1e-9);
                }
            }
        }
    }
}

#[test]
fn oxts_packets_agree_with_the_positions_they_encode() {
    let sim = StreetSimulator::new(&StreetConfig::default(), 60, 2).unwrap();
    let packets: Vec<_> = (0..60).map(|k| sim.packet(k)).collect();
    let merc = Mercator::from_reference_latitude(packets[0].lat).unwrap();
    let xy: Vec<(f64, f64)> = packets.iter().map(|p| merc.project(p.lat, p.lon)).collect();
    for k in 1..59 {
        // Central differences of the encoded positions against the velocities.
        let ve = (xy[k + 1].0 - xy[k - 1].0) / 0.2;
        let vn = (xy[k + 1].1 - xy[k - 1].1) / 0.2;
        let p = &packets[k];
        assert!(
            (ve - p.ve).abs() < 0.05 && (vn - p.vn).abs() < 0.05,
            "frame {k}"
        );
        assert!((p.vf - p.ve.hypot(p.vn)).abs() < 1e-9);
        assert!((p.al - p.vf * p.wu).abs() < 1e-12 && p.wz == p.wu);
        let e = sim.ego(k);
        assert!(((xy[k].0 - xy[0].0) - e.x).abs() < 1e-6);
        assert!(((xy[k].1 - xy[0].1) - e.y).abs() < 1e-6);
    }
    assert!(packets.iter().any(|p| p.wu.abs() > 0.2), "no turn in 6 s");
}
