//! The status line: resolution reached, rays per second, last full frame, and running jobs.

use crate::app::state::BvhscopeApp;

pub fn show(app: &BvhscopeApp, ui: &mut egui::Ui) {
    ui.horizontal(|ui| {
        match &app.shown {
            Some(s) => {
                let f = &s.frame;
                let (cols, rows) = f.grid_size();
                let res = if f.stride() <= 1 {
                    format!("full resolution {cols}×{rows}")
                } else {
                    format!("1/{} resolution ({cols}×{rows} traced)", f.stride())
                };
                ui.label(res);
                ui.separator();
                ui.label(format!("{:.1} MRays/s", s.rays_per_s / 1e6));
            }
            None => {
                ui.label("no image yet");
            }
        }
        ui.separator();
        match app.last_full_frame {
            Some(t) => ui.label(format!("last full frame {:.0} ms", t.as_secs_f64() * 1e3)),
            None => ui.label("no full frame yet"),
        };
        ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
            for job in
                [&app.jobs.render, &app.jobs.build, &app.jobs.load, &app.jobs.import, &app.jobs.film, &app.jobs.grade]
                    .into_iter()
                    .flatten()
            {
                let fraction = job.control.fraction();
                if job.control.total() > 0 {
                    ui.add(egui::ProgressBar::new(fraction).desired_width(120.0).show_percentage());
                } else {
                    ui.spinner();
                }
                ui.label(&job.label);
                ui.separator();
            }
        });
    });
}
